#!/usr/bin/env python3
"""The anatomy of reuse from render stats: per stats.json, the last frame's
temporal and spatial offers by outcome (stats.json counts.reuse), as a
markdown table.  Usage: reuse_table.py LABEL=STATS.json ..."""
import json
import sys


def pct(n, of):
    return f"{100.0 * n / of:.0f}%" if of else "-"


def main(args):
    print("| configuration | pass | offered | kept | of them on another particle | refused: another particle | off screen | miss | normal | depth | no history | M cap bound (of kept) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for arg in args:
        label, path = arg.rsplit("=", 1)
        frame = json.load(open(path))["frames"][-1]
        for name, r in sorted(frame["counts"]["reuse"].items(), reverse=True):
            o, n = r["outcomes"], r["offered"]
            print(f"| {label} (frame {frame['frame']}) | {name} | {n} | {pct(r['accepted'], n)} | "
                  f"{pct(o['other_particle'], r['accepted'])} | {pct(o['another_particle'], n)} | {pct(o['off_screen'], n)} | "
                  f"{pct(o['miss'], n)} | {pct(o['normal'], n)} | {pct(o['depth'], n)} | {pct(o['no_history'], n)} | "
                  f"{pct(r['m_capped'], r['accepted'])} |")


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    main(sys.argv[1:])
