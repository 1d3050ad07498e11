#!/usr/bin/env python3
"""Prints the README's performance table from physics_bench's CSV.

  bench/ratios.py [bench/results/latest.csv] [--all]

One row per scene: ms per step of ours and Bullet, ours/Bullet wall clock
and per awake step (the steps in which every body that can move is awake),
and the same two ratios against Bullet with our sleep thresholds
(bullet_oursleep). Each ratio is the median of the runs' ratios that
physics_bench measured, not a ratio of the medians. The fidelity scenes
(bounce, incline) only with --all.
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


def main():
    args = [arg for arg in sys.argv[1:] if not arg.startswith('--')]
    show_all = '--all' in sys.argv[1:]
    csv_path = args[0] if args else 'bench/results/latest.csv'
    scenes = {}
    with open(csv_path, newline='') as source:
        for row in csv.DictReader(source):
            scenes.setdefault(row['scene'], {})[row['engine']] = row
    print('| scene | bodies | sim s | ours ms/step | Bullet ms/step | ours/Bullet | '
          'ours/Bullet per awake step | ours/Bullet-oursleep | ours/Bullet-oursleep per awake '
          'step |')
    print('|---|---|---|---|---|---|---|---|---|')
    for scene, engines in scenes.items():
        ours = engines.get('ours')
        bullet = engines.get('bullet')
        if not ours or not bullet:
            continue
        if not show_all and scene.split('_')[0] in ('bounce', 'incline'):
            continue
        same_sleep = engines.get('bullet_oursleep')
        print(f"| {scene} | {ours['bodies']} | {float(ours['sim_seconds']):g} | "
              f"{milliseconds(ours)} | {milliseconds(bullet)} | "
              f"{ratio(bullet, 'ours_over_this_ms_per_step')} | "
              f"{ratio(bullet, 'ours_over_this_ms_per_awake_step')} | "
              f"{ratio(same_sleep, 'ours_over_this_ms_per_step')} | "
              f"{ratio(same_sleep, 'ours_over_this_ms_per_awake_step')} |")


if __name__ == '__main__':
    main()
