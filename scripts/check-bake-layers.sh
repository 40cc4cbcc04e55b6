#!/usr/bin/env bash
# The folders under bake/ form layers: none includes a folder that includes it back, and no chain of
# includes between folders comes back to where it began (building blocks below, the assembly in
# bake/pipeline/ on top). Prints each folder-to-folder include count, then every pair that includes
# each other and any longer loop; exits 1 on either, 0 otherwise.
# Usage: check-bake-layers.sh [SOURCE_ROOT]   (default: the repository this script is in)
set -euo pipefail
root="${1:-$(cd "$(dirname "$0")/.." && pwd)}"
cd "$root/bake"
edges=$(mktemp)
trap 'rm -f "$edges"' EXIT
for from in */; do
  from=${from%/}
  { grep -ho '#include "bake/[^/"]*/' "$from"/* 2>/dev/null || true; } | sed 's#.*"bake/##; s#/$##' |
    { grep -vx "$from" || true; } | sort | uniq -c | while read -r count to; do echo "$from $to $count"; done
done >"$edges"
cat "$edges"
status=0
while read -r from to count; do
  if [[ "$from" < "$to" ]] && grep -q "^$to $from " "$edges"; then
    back=$(grep "^$to $from " "$edges" | cut -d' ' -f3)
    echo "bake/$from and bake/$to include each other ($count and $back includes)"
    status=1
  fi
done <"$edges"
if ! cut -d' ' -f1,2 "$edges" | tsort >/dev/null 2>&1; then
  echo "the folders' includes form a loop:"
  cut -d' ' -f1,2 "$edges" | tsort 2>&1 >/dev/null | sed 's/^/  /'
  status=1
fi
[ "$status" = 0 ] && echo "bake/ folders: no folder includes one that includes it back, no loop"
exit "$status"
