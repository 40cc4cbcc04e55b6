# shellcheck shell=bash disable=SC2034  # the variables it sets are the sourcing script's
# Sourced by the bench/gpu scripts that bake interleaved runs: their shared options and one timed bake.

# bench_options NAME "$@": the options every such script takes into TINY (--tiny), RUNS (--runs N,
# 2), THREADS (--threads T, all cores), OUT (--out DIR, kept from the script when not given) and
# EXTRA (--extra "ARGS"), then makes OUT. A script with options of its own defines own_option, which
# sees the words left and sets TOOK to how many it took (0: not its option); any other word stops
# the script with "NAME: unknown argument".
bench_options() {
  local name=$1; shift
  TINY=0; RUNS=2; EXTRA=""; THREADS=$(nproc)
  while [ $# -gt 0 ]; do
    case $1 in
      --tiny) TINY=1 ;;
      --runs) RUNS=$2; shift ;;
      --threads) THREADS=$2; shift ;;
      --out) OUT=$2; shift ;;
      --extra) EXTRA=$2; shift ;;
      *)
        TOOK=0
        if declare -F own_option > /dev/null; then own_option "$@"; fi
        [ "$TOOK" -gt 0 ] || { echo "$name: unknown argument $1" >&2; exit 1; }
        shift $((TOOK - 1)) ;;
    esac
    shift
  done
  mkdir -p "$OUT"
}

# timed_bake LABEL ERR EXE ARGS...: "EXE bake ARGS..." with its stderr in ERR; prints the process's
# wall seconds, or on failure "LABEL failed:" and ERR's last lines on stderr and returns 1.
timed_bake() {
  local label=$1 err=$2 exe=$3 t0 t1; shift 3
  t0=$(date +%s.%N)
  if ! "$exe" bake "$@" 2>"$err"; then
    echo "$label failed:" >&2; tail -3 "$err" >&2; return 1
  fi
  t1=$(date +%s.%N)
  awk "BEGIN{printf \"%.3f\", $t1 - $t0}"
}

# workload "NAME:ARGS": sets name and args from one entry of a WORKLOADS table. The bake takes
# --target-error once: one given in --extra wins over the workload's --target-error 0.
workload() {
  name=${1%%:*}; args=${1#*:}
  case " $EXTRA " in *" --target-error "*) args=${args/ --target-error 0/} ;; esac
}
