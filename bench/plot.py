#!/usr/bin/env python3
"""Plots wall ms per step against body count, log-log, for every engine.

  bench/plot.py [bench/results/latest.csv] [bench/results/ms_per_step.png]

Left: ms per step, right: ms per awake step (the steps in which every body
that can move is awake). One line per scene family (pile, pyramid) and
engine, each of ours apart ("ours", "ours x2", "ours soft_step", "ours
soft_step x2"), from the rows of the CSV that physics_bench writes; on the
left the error bars span the min and max run. Points of scenes simulated
for less than 10 s have open markers and a note.
"""
import csv
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402


def engine_label(row):
    """The engine with, for ours, its solver and threads: each of ours is a
    line of its own, not points of one line."""
    label = row['engine']
    if row.get('solver') == 'soft_step':
        label += ' soft_step'
    if row.get('threads') not in (None, '', '1'):
        label += f" x{row['threads']}"
    return label


def main():
    csv_path = sys.argv[1] if len(sys.argv) > 1 else 'bench/results/latest.csv'
    png_path = sys.argv[2] if len(sys.argv) > 2 else 'bench/results/ms_per_step.png'
    series = {}
    with open(csv_path, newline='') as source:
        for row in csv.DictReader(source):
            family = row['scene'].split('_')[0]
            if family not in ('pile', 'pyramid') or not row['ms_per_step_median']:
                continue
            series.setdefault((family, engine_label(row)), []).append(
                (int(row['bodies']), float(row['ms_per_step_median']),
                 float(row['ms_per_step_min']), float(row['ms_per_step_max']),
                 float(row['sim_seconds']),
                 float(row['ms_per_awake_step_median'] or 'nan')))
    if not series:
        sys.exit('no pile or pyramid rows in ' + csv_path)

    figure, (wall, awake) = plt.subplots(1, 2, figsize=(12, 5))
    styles = {'ours': ('tab:blue', 'o'), 'bullet': ('tab:orange', 's'),
              'bullet_oursleep': ('tab:green', '^'), 'ours x2': ('tab:purple', 'D'),
              'ours soft_step': ('tab:red', 'v'), 'ours soft_step x2': ('tab:brown', '<')}
    lines = {'pile': '-', 'pyramid': '--'}
    shortened = set()  # sim seconds of the shortened scenes
    for (family, engine), points in sorted(series.items()):
        points.sort()
        bodies = [p[0] for p in points]
        median = [p[1] for p in points]
        below = [p[1] - p[2] for p in points]
        above = [p[3] - p[1] for p in points]
        color, marker = styles.get(engine, ('gray', 'x'))
        wall.errorbar(bodies, median, yerr=[below, above], color=color, marker=marker,
                      linestyle=lines[family], capsize=3, label=f'{engine}, {family}')
        awake.plot(bodies, [p[5] for p in points], color=color, marker=marker,
                   linestyle=lines[family], label=f'{engine}, {family}')
        # Scenes shortened to keep the run short average over their first
        # seconds only (the landing), not the whole 10 s: open markers, and
        # one note for all of them (labels beside each crowd each other).
        for point in points:
            if point[4] < 10.0:
                for axes, value in ((wall, point[1]), (awake, point[5])):
                    axes.plot(point[0], value, marker=marker, markerfacecolor='white',
                              markeredgecolor=color, linestyle='none', zorder=3)
                shortened.add(point[4])
    for axes, label, title in (
            (wall, 'wall ms per step (dt = 1/240 s)', 'ms per step (median of runs, bars: min to max)'),
            (awake, 'wall ms per awake step', 'ms per step with every moving body awake')):
        axes.set_xscale('log')
        axes.set_yscale('log')
        axes.set_xlabel('bodies')
        axes.set_ylabel(label)
        axes.set_title(title)
        axes.grid(True, which='both', alpha=0.3)
    wall.legend(fontsize=8)
    if shortened:
        seconds = ', '.join(f'{value:g}' for value in sorted(shortened))
        wall.text(0.98, 0.02, f'open markers: the first {seconds} s only (the landing), not 10 s',
                  transform=wall.transAxes, ha='right', va='bottom', fontsize=8)
    figure.tight_layout()
    figure.savefig(png_path, dpi=110)
    print('wrote ' + png_path)


if __name__ == '__main__':
    main()
