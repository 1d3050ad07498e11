#!/usr/bin/env python3
"""Prints the README's performance table from physics_bench's CSV.

  bench/ratios.py [bench/results/latest.csv] [--all]

One row per scene: ms per step of ours (one thread) and Bullet, ours/Bullet
wall clock and per awake step (the steps in which every body that can move
is awake), the same two ratios against Bullet with our sleep thresholds
(bullet_oursleep), and ours on two threads: its ms per step, its ratio to
Bullet's best per awake step (the lower of bullet and bullet_oursleep), and
ours on one thread over ours on two. Each ratio is the median of the runs'
ratios that physics_bench measured, not a ratio of the medians. The fidelity
scenes (bounce, incline) only with --all.
"""
import csv
import sys


def ratio(row, column):
    return f'{float(row[column]):.2f}' if row and row.get(column) else '–'


def milliseconds(row, column='ms_per_step_median'):
    if not row or not row.get(column):
        return '–'
    value = float(row[column])
    return f'{value:.3f}' if value < 10 else f'{value:.1f}'


def best_awake_ratio(rows, column):
    """The largest of the ratios `column` against the Bullet engines: ours
    over Bullet's best (fastest) per awake step."""
    values = [float(row[column]) for row in rows if row and row.get(column)]
    return f'{max(values):.2f}' if values else '–'


def main():
    args = [arg for arg in sys.argv[1:] if not arg.startswith('--')]
    show_all = '--all' in sys.argv[1:]
    csv_path = args[0] if args else 'bench/results/latest.csv'
    scenes = {}
    with open(csv_path, newline='') as source:
        for row in csv.DictReader(source):
            name = row['engine']
            if row.get('threads', '1') not in ('', '1'):
                name += f"_x{row['threads']}"
            scenes.setdefault(row['scene'], {})[name] = row
    print('| scene | bodies | sim s | ours ms/step | Bullet ms/step | ours/Bullet | '
          'ours/Bullet per awake step | ours/Bullet-oursleep | ours/Bullet-oursleep per awake '
          'step | ours x2 ms/step | ours x2/Bullet best per awake step | ours x1/ours x2 |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|')
    for scene, engines in scenes.items():
        ours = engines.get('ours')
        bullet = engines.get('bullet')
        if not ours or not bullet:
            continue
        if not show_all and scene.split('_')[0] in ('bounce', 'incline'):
            continue
        same_sleep = engines.get('bullet_oursleep')
        two = engines.get('ours_x2')
        print(f"| {scene} | {ours['bodies']} | {float(ours['sim_seconds']):g} | "
              f"{milliseconds(ours)} | {milliseconds(bullet)} | "
              f"{ratio(bullet, 'ours_over_this_ms_per_step')} | "
              f"{ratio(bullet, 'ours_over_this_ms_per_awake_step')} | "
              f"{ratio(same_sleep, 'ours_over_this_ms_per_step')} | "
              f"{ratio(same_sleep, 'ours_over_this_ms_per_awake_step')} | "
              f"{milliseconds(two)} | "
              f"{best_awake_ratio([bullet, same_sleep], 'ours2_over_this_ms_per_awake_step')} | "
              f"{ratio(two, 'ours_over_this_ms_per_step')} |")


if __name__ == '__main__':
    main()
