#!/usr/bin/env python3
"""Latency of one Spawn call through the running node, for a box URDF and a mesh URDF.

  bench/spawn_bench.py [--calls N] [--csv bench/results/latest.csv]

Needs the catkin workspace sourced (the rigid_body_sim service types and
package:// paths). Starts its own master on a free port and the node with
sim.launch, spawns N models of each URDF (each call timed from request to
response in this client), appends the rows to the CSV and stops everything
it started.
"""
import argparse
import csv
import os
import statistics
import sys
import time

from node_session import NodeSession

URDF_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'urdf')
MODELS = (('spawn_box', 'box.urdf'), ('spawn_mesh', 'mesh_object.urdf'))


def append_rows(csv_path, rows, calls):
    """Appends one row per model under the columns physics_bench wrote."""
    with open(csv_path, newline='') as source:
        columns = next(csv.reader(source))
    with open(csv_path, 'a', newline='') as out:
        writer = csv.DictWriter(out, fieldnames=columns, restval='')
        for scene, median, low, high in rows:
            writer.writerow({'scene': scene, 'engine': 'ours', 'threads': 1, 'bodies': 1,
                             'steps': calls, 'ms_per_step_median': median,
                             'ms_per_step_min': low, 'ms_per_step_max': high})


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--calls', type=int, default=20)
    parser.add_argument('--csv', default='')
    args = parser.parse_args()

    with NodeSession('spawn_bench') as rospy:
        from geometry_msgs.msg import Pose, Twist
        from rigid_body_sim.srv import Spawn, SpawnRequest

        rospy.wait_for_service('/rigid_body_sim/spawn', timeout=60.0)
        spawn = rospy.ServiceProxy('/rigid_body_sim/spawn', Spawn, persistent=True)
        rows = []
        print('spawn latency through the node (client-side wall time of one call), '
              f'{args.calls} calls per model')
        print(f'{"scene":<11} {"urdf":<17} {"first ms":>9} {"median ms":>10} {"min ms":>8} '
              f'{"max ms":>8}')
        for index, (scene, urdf) in enumerate(MODELS):
            times = []
            for call in range(args.calls):
                request = SpawnRequest()
                request.name = f'{scene}_{call}'
                request.urdf_path = os.path.abspath(os.path.join(URDF_DIR, urdf))
                request.pose = Pose()
                # Far apart, so the models never touch each other.
                request.pose.position.x = 3.0 * call
                request.pose.position.y = 3.0 * index
                request.pose.position.z = 1.0
                request.pose.orientation.w = 1.0
                request.twist = Twist()
                request.friction = -1.0
                request.restitution = -1.0
                start = time.perf_counter()
                response = spawn(request)
                times.append(1e3 * (time.perf_counter() - start))
                if not response.success:
                    sys.exit(f'{scene}: spawn refused: {response.message}')
            median = statistics.median(times)
            print(f'{scene:<11} {urdf:<17} {times[0]:9.2f} {median:10.2f} {min(times):8.2f} '
                  f'{max(times):8.2f}')
            rows.append((scene, median, min(times), max(times)))
        if args.csv:
            append_rows(args.csv, rows, args.calls)


if __name__ == '__main__':
    main()
