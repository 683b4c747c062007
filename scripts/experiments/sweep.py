#!/usr/bin/env python3
"""Runs an automata config over many seeds and checks issue 14's bars on each best tree.

    scripts/experiments/sweep.py CONFIG.toml [--seeds 1-24] [--out DIR] [-- EVOLVE ARGS...]

For each seed: `sylva evolve CONFIG --seed S --out DIR/sS` (skipped when DIR/sS/stats.csv
already has the last generation), then `sylva grow DIR/sS/best.json -o best.skeleton.json`
(the full plant, every step a segment), and reads back:

- shape: the last generation's F_pos and F_num (stats.csv); met when F_num <= 2 and
  F_pos <= 20;
- levels: first-order branches and each one's sub-branches (a branch is a lateral
  segment; a sub-branch is a lateral segment of order 2 under it); per branch met when
  the first-order count is within 20% of B and every first-order branch has at least
  0.8 x E sub-branches (B and E from `--levels B,E`);
- taper, on woody segments along every path from the foot: the thickness never grows,
  every tip is at most a quarter of the foot's, and no segment is less than half as thick
  as the one before it.

Prints one line per seed and a summary. Needs target/release/sylva (cargo build --release).
"""

import argparse
import csv
import json
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SYLVA = os.environ.get("SYLVA", os.path.join(ROOT, "target", "release", "sylva"))
# Radii are 32-bit floats: equal thicknesses may differ in the last bit.
EPS = 1e-6


def seeds(text):
    out = []
    for part in text.split(","):
        a, _, b = part.partition("-")
        out.extend(range(int(a), int(b or a) + 1))
    return out


def last_stats(path):
    with open(path) as f:
        rows = list(csv.DictReader(f))
    return rows[-1] if rows else None


def levels(segments):
    """First-order branches and each one's sub-branch count."""
    branch_of = [None] * len(segments)
    subs = {}
    for i, s in enumerate(segments):
        p = s["parent"]
        inherited = branch_of[p] if p is not None and p < i else None
        if s["lateral"] and s["order"] == 1:
            branch_of[i] = i
            subs[i] = 0
        else:
            branch_of[i] = inherited
            if s["lateral"] and s["order"] == 2 and inherited is not None:
                subs[inherited] += 1
    return sorted(subs.values(), reverse=True)


def taper(segments):
    """(never grows, tips <= foot / 4, no halving step, worst tip/foot, worst step ratio)."""
    woody = [s for s in segments if s["woody"]]
    if not woody:
        return (False, False, False, None, None)
    foot = max(s["start_radius"] for s in woody if s["parent"] is None)
    grows = halving = False
    worst_step = 1.0
    has_child = [False] * len(segments)
    for i, s in enumerate(segments):
        if not s["woody"]:
            continue
        before = [s["start_radius"]]
        p = s["parent"]
        if p is not None:
            has_child[p] = has_child[p] or segments[p]["woody"]
            if segments[p]["woody"]:
                before.insert(0, segments[p]["end_radius"])
        chain = before + [s["end_radius"]]
        for a, b in zip(chain, chain[1:]):
            if b > a * (1 + EPS):
                grows = True
            if a > 0:
                worst_step = min(worst_step, b / a)
                if b < 0.5 * a * (1 - EPS):
                    halving = True
    tips = [s["end_radius"] for i, s in enumerate(segments) if s["woody"] and not has_child[i]]
    worst_tip = max(tips) / foot if foot > 0 else None
    return (not grows, worst_tip is not None and worst_tip <= 0.25 + 1e-5, not halving,
            worst_tip, worst_step)


def contact_sheet(out, seed_list, path, view):
    """Renders each seed's best at 200 x 200 and tiles them, seeds in order, 6 to a row."""
    tiles = []
    for seed in seed_list:
        tile = os.path.join(out, f"s{seed}", f"sheet-{view}.png")
        subprocess.run([SYLVA, "render", os.path.join(out, f"s{seed}", "best.json"), "-o", tile,
                        "--size", "200x200", "--view", view], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        tiles.append(tile)
    rows = []
    for i in range(0, len(tiles), 6):
        row = os.path.join(out, f"row-{i // 6}.png")
        subprocess.run(["convert", *tiles[i:i + 6], "+append", row], check=True)
        rows.append(row)
    subprocess.run(["convert", *rows, "-append", path], check=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("config")
    ap.add_argument("--seeds", default="1-24")
    ap.add_argument("--out", default=None)
    ap.add_argument("--levels", default=None, help="B,E: B first-order branches with E each")
    ap.add_argument("--taper", action="store_true", help="check the taper bars")
    ap.add_argument("--sheet", default=None,
                    help="also write a contact sheet: each seed's best, 6 to a row (ImageMagick)")
    ap.add_argument("--view", default="iso", help="camera of the contact sheet")
    ap.add_argument("rest", nargs="*", help="more `sylva evolve` arguments, after --")
    a = ap.parse_args()
    name = os.path.splitext(os.path.basename(a.config))[0]
    out = a.out or os.path.join("/tmp", "sweep-" + name)
    rows = []
    for seed in seeds(a.seeds):
        d = os.path.join(out, f"s{seed}")
        stats = os.path.join(d, "stats.csv")
        if not os.path.exists(stats) or not os.path.exists(os.path.join(d, "best.json")):
            subprocess.run([SYLVA, "evolve", a.config, "--seed", str(seed), "--out", d,
                            *a.rest], check=True, stdout=subprocess.DEVNULL,
                           stderr=subprocess.DEVNULL)
        skel = os.path.join(d, "best.skeleton.json")
        subprocess.run([SYLVA, "grow", os.path.join(d, "best.json"), "-o", skel], check=True,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        with open(skel) as f:
            segments = json.load(f)["segments"]
        last = last_stats(stats)
        f_pos, f_num = float(last["f_pos"]), float(last["f_num"])
        row = {"seed": seed, "generation": int(last["generation"]), "f_pos": f_pos,
               "f_num": f_num, "f_thick": float(last["f_thick"]),
               "shape": f_num <= 2 and f_pos <= 20}
        line = (f"seed {seed:2}: gen {row['generation']:3}  F_pos {f_pos:6.1f}  F_num "
                f"{f_num:4.0f}  F_thick {row['f_thick']:.3f}  shape {'ok' if row['shape'] else '--'}")
        if a.levels:
            b, e = (int(x) for x in a.levels.split(","))
            subs = levels(segments)
            row["levels"] = (abs(len(subs) - b) <= 0.2 * b
                             and all(n >= 0.8 * e for n in subs) and len(subs) > 0)
            row["level_totals"] = (abs(len(subs) - b) <= 0.2 * b
                                   and abs(sum(subs) - b * e) <= 0.2 * b * e)
            line += f"  branches {len(subs)} subs {subs}  per-branch {'ok' if row['levels'] else '--'}"
        if a.taper:
            never_grows, tips, gradual, tip, step = taper(segments)
            row["taper"] = never_grows and tips and gradual
            row["both"] = row["taper"] and row["shape"]
            line += (f"  taper {'ok' if row['taper'] else '--'} (grows {'no' if never_grows else 'YES'},"
                     f" tip/foot {tip if tip is None else round(tip, 3)}, worst step "
                     f"{step if step is None else round(step, 3)})")
        print(line, flush=True)
        rows.append(row)
    if a.sheet:
        contact_sheet(out, [r["seed"] for r in rows], a.sheet, a.view)
    n = len(rows)
    summary = f"{n} seeds: shape met {sum(r['shape'] for r in rows)}/{n}"
    if a.levels:
        summary += (f", per branch {sum(r['levels'] for r in rows)}/{n}, per-level totals "
                    f"{sum(r['level_totals'] for r in rows)}/{n}")
    if a.taper:
        summary += (f", taper {sum(r['taper'] for r in rows)}/{n}, shape and taper "
                    f"{sum(r['both'] for r in rows)}/{n}")
    print(summary)
    return 0


if __name__ == "__main__":
    sys.exit(main())
