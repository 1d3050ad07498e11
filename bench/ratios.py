#!/usr/bin/env python3
"""Prints the README's performance table from physics_bench's CSV.

  bench/ratios.py [bench/results/latest.csv] [--all]

One row per scene: ms per step of ours (one thread) and Bullet, ours/Bullet
wall clock and per awake step (the steps in which every body that can move
is awake), the same two ratios against Bullet with our sleep thresholds
(bullet_oursleep), and ours on two threads: its ms per step, its ratio to
Bullet's best per awake step (the lower of bullet and bullet_oursleep), and
ours on one thread over ours on two; then ours with the soft step
(solver column soft_step) on one and on two threads: each one's ms per step
and its ratio to Bullet's best per awake step. Bullet's best is the faster
of bullet and bullet_oursleep whose runs did not diverge. Each ratio is the
median of the runs' ratios that physics_bench measured, not a ratio of the
medians. The fidelity scenes (bounce, incline) only with --all.

The articulated scenes (those whose rows carry an energy drift) get a table
of their own, one row per scene and step rate: each engine's ms per step
beside its energy drift (or servo error, where motors hold or drive the
arm), "diverged" where a run's energy grew by more than 10 % of the scene's
scale or turned non-finite, and ours against the fastest other engine that
did not diverge, named; then the same for ours with the soft step.

A CSV from before the solver column reads as all exact.
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
    """The largest of the ratios `column` against the Bullet engines that
    did not diverge: ours over Bullet's best (fastest) per awake step."""
    values = [float(row[column]) for row in rows
              if row and row.get(column) and not diverged(row)]
    return f'{max(values):.2f}' if values else '–'


# The soft step last, so that the columns before it stay where they were.
ARTICULATED_ENGINES = [('ours', 'ours'), ('bullet', 'Bullet btMultiBody'),
                       ('mujoco_rk4', 'MuJoCo RK4'), ('mujoco_euler', 'MuJoCo Euler'),
                       ('ours_soft', 'ours soft step')]


def diverged(row):
    return bool(row and row.get('diverged_runs') and int(row['diverged_runs']) > 0)


def articulated_cell(row):
    """ms per step, then the energy drift [largest growth] in % of the
    scene's energy scale, or the servo error where the arm has motors."""
    if not row:
        return '–'
    figures = (f"{100 * float(row['energy_drift']):+.2g} % "
               f"[{100 * float(row['energy_growth']):.2g} %]")
    if row.get('servo_error_rad') and float(row['servo_error_rad']) > 0:
        figures += f", servo {float(row['servo_error_rad']):.2g} rad"
    mark = ', **diverged**' if diverged(row) else ''
    return f'{milliseconds(row)} ({figures}{mark})'


def fastest_undiverged(engines):
    """The other engine (not ours) that did not diverge with the lowest ms
    per step: (its label, its row), or None."""
    candidates = [(float(row['ms_per_step_median']), row['label'], row)
                  for name, row in engines.items()
                  if name != 'ours' and not name.startswith('ours_') and row
                  and row.get('ms_per_step_median') and not diverged(row)]
    if not candidates:
        return None
    _, label, row = min(candidates, key=lambda candidate: candidate[0])
    return label, row


def print_articulated(scenes):
    print('| scene | dt s | ' + ' | '.join(f'{label} ms/step (energy drift [growth])'
                                          for _, label in ARTICULATED_ENGINES) +
          ' | fastest other engine not diverged | ours/it | soft step/it |')
    print('|---|---|' + '---|' * len(ARTICULATED_ENGINES) + '---|---|---|')
    for scene, engines in scenes.items():
        ours = engines.get('ours')
        if not ours or not ours.get('energy_drift'):
            continue
        best = fastest_undiverged(engines)
        if best is None:
            against, ratio_text, soft_text = 'none', '–', '–'
        else:
            against = best[0]
            ratio_text = ('– (ours diverged)' if diverged(ours)
                          else ratio(best[1], 'ours_over_this_ms_per_step'))
            soft_text = soft_over_fastest(engines.get('ours_soft'), best[1])
        step = float(ours['time_step_s']) if ours.get('time_step_s') else 1 / 240
        print(f'| {scene} | 1/{round(1 / step)} | ' +
              ' | '.join(articulated_cell(engines.get(name)) for name, _ in ARTICULATED_ENGINES) +
              f' | {against} | {ratio_text} | {soft_text} |')


def soft_over_fastest(soft, fastest):
    """Ours with the soft step over the fastest other engine, or why there
    is no ratio."""
    if not soft:
        return '–'
    return ('– (soft step diverged)' if diverged(soft)
            else ratio(fastest, 'soft_over_this_ms_per_step'))


def main():
    args = [arg for arg in sys.argv[1:] if not arg.startswith('--')]
    show_all = '--all' in sys.argv[1:]
    csv_path = args[0] if args else 'bench/results/latest.csv'
    scenes = {}
    with open(csv_path, newline='') as source:
        for row in csv.DictReader(source):
            name = row['engine']
            if row.get('solver') == 'soft_step':
                name += '_soft'
            if row.get('threads', '1') not in ('', '1'):
                name += f"_x{row['threads']}"
            if row['engine'] == 'bullet_oursleep':
                name_label = 'Bullet btMultiBody, our sleep'
            else:
                name_label = dict(ARTICULATED_ENGINES).get(name, name)
            row['label'] = name_label
            scenes.setdefault(row['scene'], {})[name] = row
    free_body = [scene for scene, engines in scenes.items()
                 if engines.get('ours') and not engines['ours'].get('energy_drift')]
    if free_body:
        print_free_body(scenes, show_all)
    if len(free_body) < len(scenes):
        if free_body:
            print()
        print_articulated(scenes)


def print_free_body(scenes, show_all):
    print('| scene | bodies | sim s | ours ms/step | Bullet ms/step | ours/Bullet | '
          'ours/Bullet per awake step | ours/Bullet-oursleep | ours/Bullet-oursleep per awake '
          'step | ours x2 ms/step | ours x2/Bullet best per awake step | ours x1/ours x2 | '
          'soft step ms/step | soft step/Bullet best per awake step | soft step x2 ms/step | '
          'soft step x2/Bullet best per awake step |')
    print('|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|')
    for scene, engines in scenes.items():
        ours = engines.get('ours')
        bullet = engines.get('bullet')
        if not ours or not bullet or ours.get('energy_drift'):
            continue
        if not show_all and scene.split('_')[0] in ('bounce', 'incline'):
            continue
        same_sleep = engines.get('bullet_oursleep')
        two = engines.get('ours_x2')
        soft = engines.get('ours_soft')
        soft_two = engines.get('ours_soft_x2')
        print(f"| {scene} | {ours['bodies']} | {float(ours['sim_seconds']):g} | "
              f"{milliseconds(ours)} | {milliseconds(bullet)} | "
              f"{ratio(bullet, 'ours_over_this_ms_per_step')} | "
              f"{ratio(bullet, 'ours_over_this_ms_per_awake_step')} | "
              f"{ratio(same_sleep, 'ours_over_this_ms_per_step')} | "
              f"{ratio(same_sleep, 'ours_over_this_ms_per_awake_step')} | "
              f"{milliseconds(two)} | "
              f"{best_awake_ratio([bullet, same_sleep], 'ours2_over_this_ms_per_awake_step')} | "
              f"{ratio(two, 'ours_over_this_ms_per_step')} | "
              f"{milliseconds(soft)} | "
              f"{best_awake_ratio([bullet, same_sleep], 'soft_over_this_ms_per_awake_step')} | "
              f"{milliseconds(soft_two)} | "
              f"{best_awake_ratio([bullet, same_sleep], 'soft2_over_this_ms_per_awake_step')} |")


if __name__ == '__main__':
    main()
