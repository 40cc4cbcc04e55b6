#!/usr/bin/env bash
# Sharded bake on a real (one-node, scratch-folder) Slurm cluster: the sample baked with the default
# settings as a 4-task array plus a dependent merge job must equal the single-machine bake byte for
# byte, and so must a bake that refines by check, finished by its own command (--from-shards); then
# one shard's task is killed, the failure is reported with its task id, and re-running that shard
# alone completes the bake. The cluster is stopped whatever happens; every wait is bounded.
#   tests/slurm/slurm_shards_test.sh GIBAKE_EXE   (exit 77: Slurm or munge not installed)
set -euo pipefail
src="$(cd "$(dirname "$0")/../.." && pwd)"
gibake="$(realpath "${1:-$src/build/cli/gibake}")"
scene="$src/samples/cornell/cornell.gltf"
# Every default (the fitted grid, adaptive rays, the ray budget, the detail-volume rule): 576 probes,
# two blocks of 512 and 64, so shards 1 and 3 of 4 own one each.
opts=(--ddgi)
scratch="$(mktemp -d /tmp/gibake-slurm-test.XXXXXX)"
cluster="$scratch/cluster"
cleanup() {
  timeout 60 "$src/scripts/slurm-local-cluster.sh" stop "$cluster" || true
  rm -rf "$scratch"
}
trap cleanup EXIT
fail() { echo "slurm_shards_test: FAIL: $*" >&2; exit 1; }

set +e
timeout 60 "$src/scripts/slurm-local-cluster.sh" start "$cluster" >/dev/null
rc=$?
set -e
[ $rc = 77 ] && { echo "slurm_shards_test: skipped (Slurm/munge not installed)"; exit 77; }
[ $rc = 0 ] || fail "the cluster did not start (logs: $cluster/log)"
export SLURM_CONF="$cluster/slurm.conf"
cd "$scratch"

echo "== single-machine bake"
timeout 120 "$gibake" "$scene" "${opts[@]}" --out single.gibake --progress lines 2>/dev/null

echo "== 4 shards as a Slurm array + dependent merge"
timeout 180 "$src/scripts/gibake-slurm" "$scene" "${opts[@]}" --out sharded.gibake --shards 4 \
  --gibake "$gibake" --wait --timeout 150 --depfile sharded.d
cmp single.gibake sharded.gibake || fail "the merged bake differs from the single-machine bake"
# The depfile's rule names the merged output (shard 0's names its part) and the scene.
[ "$(head -n 1 sharded.d)" = "$(realpath sharded.gibake): \\" ] || fail "the depfile's target: $(head -n 1 sharded.d)"
grep -qF "$(realpath "$scene")" sharded.d || fail "the depfile does not list the scene"
echo "identical: $(stat -c %s sharded.gibake) bytes"

echo "== refinement by check: 3 shards, finished by the bake's own command (--from-shards)"
checked=(--ddgi --rays 64 --refine-budget 1024 --refine-by-check 4096 --check-patches 8 --check-rays 32)
timeout 120 "$gibake" "$scene" "${checked[@]}" --out checked_single.gibake --progress lines 2>/dev/null
timeout 180 "$src/scripts/gibake-slurm" "$scene" "${checked[@]}" --out checked.gibake --shards 3 \
  --gibake "$gibake" --wait --timeout 150
grep -q -- "--from-shards" checked.gibake.slurm/merge.sbatch || fail "the finishing job is not the bake's --from-shards"
cmp checked_single.gibake checked.gibake || fail "the bake finished from the shards differs from the single-machine bake"
echo "identical: $(stat -c %s checked.gibake) bytes"

echo "== shard 1's task killed"
# A gibake that holds shard 1 while ./hold exists, so that its task is still running when cancelled.
printf '#!/bin/sh\ncase " $* " in *" --shard 1/4 "*) while [ -e "%s/hold" ]; do sleep 0.2; done ;; esac\nexec "%s" "$@"\n' \
  "$scratch" "$gibake" > gibake-held
chmod +x gibake-held
touch hold
set +e
timeout 180 "$src/scripts/gibake-slurm" "$scene" "${opts[@]}" --out killed.gibake --shards 4 \
  --gibake "$scratch/gibake-held" --wait --timeout 150 2> killed.err &
submit=$!
set -e
task=""
for _ in $(seq 300); do  # at most 60 s for shard 1's task to run
  task="$(awk '$1 == 1 { print $2 }' killed.gibake.slurm/tasks 2>/dev/null || true)"
  [ -n "$task" ] && [ "$(squeue -h -j "$task" -o %T 2>/dev/null)" = RUNNING ] && break
  sleep 0.2
done
[ -n "$task" ] || fail "shard 1 never ran"
scancel "$task"
echo "cancelled task $task"
set +e
wait $submit
rc=$?
set -e
cat killed.err
[ $rc = 4 ] || fail "gibake-slurm --wait returned $rc for a failed shard (expected 4)"
[ ! -e killed.gibake ] || fail "an output was written although a shard failed"
grep -q "shard 1 of 4 failed (Slurm task $task)" killed.err || fail "the failed shard was not reported with its task id"
[ "$(grep -c 'failed (Slurm task' killed.err)" = 1 ] || fail "more than shard 1 reported as failed"
grep -q -- "--rerun" killed.err || fail "no re-run command printed"

echo "== re-run of shard 1 alone"
rm -f hold
timeout 180 "$src/scripts/gibake-slurm" --rerun killed.gibake.slurm --wait --timeout 150 2> rerun.err
cat rerun.err
grep -q "re-running shard(s) 1 of 4" rerun.err || fail "the re-run did not take shard 1 alone"
cmp single.gibake killed.gibake || fail "the bake completed by the re-run differs from the single-machine bake"
echo "slurm_shards_test: passed"
