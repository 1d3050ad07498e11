#!/usr/bin/env python3
"""Plots wall ms per step against body count, log-log, for both engines.

  bench/plot.py [bench/results/latest.csv] [bench/results/ms_per_step.png]

One line per scene family (pile, pyramid) and engine, from the rows of the
CSV that physics_bench writes; the error bars span the min and max run.
Points of scenes simulated for less than 10 s have open markers and a note.
"""
import csv
import sys

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402


def main():
    csv_path = sys.argv[1] if len(sys.argv) > 1 else 'bench/results/latest.csv'
    png_path = sys.argv[2] if len(sys.argv) > 2 else 'bench/results/ms_per_step.png'
    series = {}
    with open(csv_path, newline='') as source:
        for row in csv.DictReader(source):
            family = row['scene'].split('_')[0]
            if family not in ('pile', 'pyramid') or not row['ms_per_step_median']:
                continue
            series.setdefault((family, row['engine']), []).append(
                (int(row['bodies']), float(row['ms_per_step_median']),
                 float(row['ms_per_step_min']), float(row['ms_per_step_max']),
                 float(row['sim_seconds'])))
    if not series:
        sys.exit('no pile or pyramid rows in ' + csv_path)

    figure, axes = plt.subplots(figsize=(7, 5))
    styles = {'ours': ('tab:blue', 'o'), 'bullet': ('tab:orange', 's')}
    lines = {'pile': '-', 'pyramid': '--'}
    shortened = set()  # sim seconds of the shortened scenes
    for (family, engine), points in sorted(series.items()):
        points.sort()
        bodies = [p[0] for p in points]
        median = [p[1] for p in points]
        below = [p[1] - p[2] for p in points]
        above = [p[3] - p[1] for p in points]
        color, marker = styles.get(engine, ('gray', 'x'))
        axes.errorbar(bodies, median, yerr=[below, above], color=color, marker=marker,
                      linestyle=lines[family], capsize=3, label=f'{engine}, {family}')
        # Scenes shortened to keep the run short average over their first
        # seconds only (the landing), not the whole 10 s: open markers, and
        # one note for all of them (labels beside each crowd each other).
        for point in points:
            if point[4] < 10.0:
                axes.plot(point[0], point[1], marker=marker, markerfacecolor='white',
                          markeredgecolor=color, linestyle='none', zorder=3)
                shortened.add(point[4])
    axes.set_xscale('log')
    axes.set_yscale('log')
    axes.set_xlabel('bodies')
    axes.set_ylabel('wall ms per step (dt = 1/240 s)')
    axes.set_title('ms per step against body count (median of runs, bars: min to max)')
    axes.grid(True, which='both', alpha=0.3)
    axes.legend()
    if shortened:
        seconds = ', '.join(f'{value:g}' for value in sorted(shortened))
        axes.text(0.98, 0.02, f'open markers: the first {seconds} s only (the landing), not 10 s',
                  transform=axes.transAxes, ha='right', va='bottom', fontsize=8)
    figure.tight_layout()
    figure.savefig(png_path, dpi=110)
    print('wrote ' + png_path)


if __name__ == '__main__':
    main()
