#!/usr/bin/env python3
"""The table after interleaved bench/gpu runs, from OUT/walls.txt: for each runner (the COLUMNS - 2
words of a line before its run and its wall seconds), the best wall time beside every run's, and
that run's stages (timings_s of the --progress json summary in OUT/<runner words joined by dots>.<run>.err)
and its messages that hold any of WORDS. Lines of another length, and comments, are passed over.

Usage: walls.py OUT COLUMNS [WORD...]
"""
import json
import os
import sys

out, columns, words = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
walls = {}
for line in open(os.path.join(out, "walls.txt")):
    parts = line.split()
    if line.startswith("#") or len(parts) != columns: continue
    try: walls.setdefault(tuple(parts[:-2]), []).append((float(parts[-1]), parts[-2]))
    except ValueError: pass
for key, runs in walls.items():
    best, run = min(runs)
    summary, notes = {}, []
    for line in open(os.path.join(out, f"{'.'.join(key)}.{run}.err")):
        try: e = json.loads(line)
        except ValueError: continue
        if e.get("event") == "summary": summary = e
        elif any(w in str(e.get("message", "")) for w in words): notes.append(e["message"])
    print(f"\n{' '.join(key)}: wall {best:.2f} s (runs {', '.join(f'{w:.2f}' for w, _ in sorted(runs, key=lambda r: r[1]))})")
    for stage, sec in summary.get("timings_s", {}).items(): print(f"  {stage:44s} {sec:8.3f} s")
    for n in notes: print(f"  | {n}")
