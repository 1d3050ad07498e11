#!/usr/bin/env python3
"""Time of one ~ray_cast call of 100,000 rays through the running node.

  bench/ray_service_bench.py [--rays N] [--calls N] [--client PATH]

ray_bench's scene through the node's public interface: a static terrain of
99,458 triangles (100 m square, 0.5 m waves, written as an OBJ file), 1,000
static boxes of 0.5 m at 1.5 m, and rays cast down at random slants from
3 m. Needs the catkin workspace sourced. Starts its own master and the node
with sim.launch (one physics thread, ~threads' default), and prints the
best round trip, what this Python client spends encoding the request and
decoding the answer (genpy, measured apart on the same messages), and the
rest: the node's own time and the transport.

With --client, the C++ client bench/ray_service_client.cc (built by `make
bench`) runs instead, under the same master and node: it spawns ray_bench's
own scene and rays, so that the round trip is timed without genpy's
decoding, and checks the first hits against the exact ones.
"""
import argparse
import io
import math
import os
import random
import subprocess
import tempfile
import time

from node_session import NodeSession

CELLS = 223  # terrain cells per side: 2 * 223^2 triangles
SIZE = 100.0  # m
BOXES = 1000


def write_terrain(path):
    with open(path, 'w') as out:
        for i in range(CELLS + 1):
            for j in range(CELLS + 1):
                x = SIZE * i / CELLS - SIZE / 2
                y = SIZE * j / CELLS - SIZE / 2
                out.write('v %.17g %.17g %.17g\n' % (x, y, 0.5 * math.sin(0.3 * x) * math.cos(0.2 * y)))
        vertex = lambda i, j: i * (CELLS + 1) + j + 1  # OBJ counts from 1
        for i in range(CELLS):
            for j in range(CELLS):
                out.write('f %d %d %d\n' % (vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1)))
                out.write('f %d %d %d\n' % (vertex(i, j), vertex(i + 1, j + 1), vertex(i, j + 1)))


def spawn_scene(terrain_path):
    from geometry_msgs.msg import Pose
    import rospy
    from rigid_body_sim.srv import Spawn, SpawnRequest
    rospy.wait_for_service('/rigid_body_sim/spawn', timeout=60.0)
    spawn = rospy.ServiceProxy('/rigid_body_sim/spawn', Spawn, persistent=True)
    pose = Pose()
    pose.orientation.w = 1.0
    terrain = ('<robot name="terrain"><link name="ground"><collision><geometry>'
               f'<mesh filename="file://{terrain_path}"/></geometry></collision></link></robot>')
    answer = spawn(SpawnRequest(name='terrain', urdf=terrain, pose=pose, is_static=True,
                                friction=-1.0, restitution=-1.0))
    if not answer.success:
        raise SystemExit(f'terrain refused: {answer.message}')
    box = ('<robot name="box"><link name="box"><collision><geometry><box size="0.5 0.5 0.5"/>'
           '</geometry></collision></link></robot>')
    place = random.Random(3)
    for k in range(BOXES):
        pose = Pose()
        pose.position.x = place.uniform(-40.0, 40.0)
        pose.position.y = place.uniform(-40.0, 40.0)
        pose.position.z = 1.5
        pose.orientation.w = 1.0
        answer = spawn(SpawnRequest(name=f'box_{k}', urdf=box, pose=pose, is_static=True,
                                    friction=-1.0, restitution=-1.0))
        if not answer.success:
            raise SystemExit(f'box {k} refused: {answer.message}')


def make_request(rays):
    from geometry_msgs.msg import Point, Vector3
    from rigid_body_sim.srv import RayCastRequest
    place = random.Random(5)
    request = RayCastRequest(max_distance=100.0)
    for _ in range(rays):
        request.origins.append(Point(place.uniform(-40.0, 40.0), place.uniform(-40.0, 40.0), 3.0))
        d = (place.uniform(-40.0, 40.0), place.uniform(-40.0, 40.0), -40.0)
        norm = math.sqrt(sum(c * c for c in d))
        request.directions.append(Vector3(d[0] / norm, d[1] / norm, d[2] / norm))
    return request


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--rays', type=int, default=100000)
    parser.add_argument('--calls', type=int, default=5)
    parser.add_argument('--client', help='the C++ client (ray_service_client) to run instead')
    args = parser.parse_args()
    if args.client:
        with NodeSession('ray_service_bench'):
            result = subprocess.run([args.client, str(args.rays), str(args.calls)])
        raise SystemExit(result.returncode)
    with NodeSession('ray_service_bench') as rospy:
        from rigid_body_sim.srv import RayCast, RayCastResponse
        with tempfile.TemporaryDirectory() as scratch:
            terrain_path = os.path.join(scratch, 'terrain.obj')
            write_terrain(terrain_path)
            spawn_scene(terrain_path)
        request = make_request(args.rays)
        cast = rospy.ServiceProxy('/rigid_body_sim/ray_cast', RayCast, persistent=True)
        best = float('inf')
        for _ in range(args.calls):
            start = time.perf_counter()
            answer = cast(request)
            best = min(best, time.perf_counter() - start)
        # The client's own share, each the best of three like the round trip.
        encode = decode = float('inf')
        reply = io.BytesIO()
        answer.serialize(reply)
        for _ in range(3):
            start = time.perf_counter()
            request.serialize(io.BytesIO())
            encode = min(encode, time.perf_counter() - start)
            start = time.perf_counter()
            RayCastResponse().deserialize(reply.getvalue())
            decode = min(decode, time.perf_counter() - start)
        print(f'ray_cast through the node: {args.rays} rays, {sum(answer.hit)} hits; best of '
              f'{args.calls} round trips {1e3 * best:.1f} ms; this client encodes '
              f'{1e3 * encode:.1f} ms and decodes {1e3 * decode:.1f} ms; the node and the '
              f'transport {1e3 * (best - encode - decode):.1f} ms')


if __name__ == '__main__':
    main()
