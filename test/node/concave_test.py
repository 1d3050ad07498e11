#!/usr/bin/env python3
"""Concave meshes through the ROS interface (issue 24).

Moving meshes that are clearly not convex collide as convex pieces (a mug
holds a ball; an L-bracket straddles a box on its two feet); static meshes
collide as their triangles (a box lands on a bin's floor; a ball rolls under
a table). Every scene has its own place in the world, so they do not meet.
Run by concave_test.test: the node starts paused and the test steps it.
The meshes come from test/data/make_decomposition_meshes.py.
"""

import math
import os
import random
import struct
import tempfile
import time
import unittest

import rospkg
import rospy
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3
from rigid_body_sim.srv import Delete, GetPhysics, GetState, Spawn, SpawnRequest, Step

PKG = 'rigid_body_sim'
SIM = '/rigid_body_sim/'
GRAVITY = 9.81  # m/s^2, the node's default
CONTACT_SLOP = 0.001  # m: resting bodies sink at most this far into what holds them


def service(name, service_type):
    rospy.wait_for_service(SIM + name, timeout=60)
    return rospy.ServiceProxy(SIM + name, service_type)


def mesh_urdf(name, mesh_path, mode=None):
    """A one-link model colliding as the mesh, mass from its geometry."""
    gazebo = ('<gazebo reference="body"><mesh_collision>%s</mesh_collision></gazebo>' % mode
              if mode else '')
    return ('<robot name="%s"><link name="body"><collision><geometry><mesh filename="%s"/>'
            '</geometry></collision></link>%s</robot>' % (name, mesh_path, gazebo))


def primitive_urdf(name, geometry):
    return ('<robot name="%s"><link name="body"><collision><geometry>%s</geometry></collision>'
            '</link></robot>' % (name, geometry))


def pose(x, y, z, pitch=0.0):
    """A pose turned by `pitch` about the world y axis."""
    return Pose(Point(x, y, z), Quaternion(0.0, math.sin(pitch / 2), 0.0, math.cos(pitch / 2)))


# The terrain of test_boxes_rest_on_a_terrain: a 10 m square of 224 x 224
# cells (100,352 triangles), each cell split along its (i, j)-(i+1, j+1)
# diagonal, over z = TERRAIN_BASE + A (sin(2 pi x / 2.5) + sin(2 pi y / 1.6)),
# hills of +-5 cm, its surface about 0.48 m above the ground plane.
TERRAIN_CELLS = 224
TERRAIN_SIDE = 10.0  # m
TERRAIN_BASE = 0.48  # m
TERRAIN_AMPLITUDE = 0.025  # m


def hills(x, y):
    return TERRAIN_BASE + TERRAIN_AMPLITUDE * (math.sin(2.0 * math.pi * x / 2.5) +
                                               math.sin(2.0 * math.pi * y / 1.6))


def terrain_height(x, y):
    """The triangulated surface at (x, y) (terrain frame): the linear
    interpolant of hills over the cell's triangle."""
    cell = TERRAIN_SIDE / TERRAIN_CELLS
    u = (x + 0.5 * TERRAIN_SIDE) / cell
    v = (y + 0.5 * TERRAIN_SIDE) / cell
    i = min(max(int(math.floor(u)), 0), TERRAIN_CELLS - 1)
    j = min(max(int(math.floor(v)), 0), TERRAIN_CELLS - 1)
    fu, fv = u - i, v - j
    x0, y0 = -0.5 * TERRAIN_SIDE + i * cell, -0.5 * TERRAIN_SIDE + j * cell
    h00, h11 = hills(x0, y0), hills(x0 + cell, y0 + cell)
    if fu >= fv:  # below the diagonal: (i, j), (i+1, j), (i+1, j+1)
        h10 = hills(x0 + cell, y0)
        return h00 + fu * (h10 - h00) + fv * (h11 - h10)
    h01 = hills(x0, y0 + cell)  # above it: (i, j), (i+1, j+1), (i, j+1)
    return h00 + fv * (h01 - h00) + fu * (h11 - h01)


def write_terrain_stl(path):
    n = TERRAIN_CELLS
    cell = TERRAIN_SIDE / n
    corner = [[(-0.5 * TERRAIN_SIDE + i * cell, -0.5 * TERRAIN_SIDE + j * cell,
                hills(-0.5 * TERRAIN_SIDE + i * cell, -0.5 * TERRAIN_SIDE + j * cell))
               for j in range(n + 1)] for i in range(n + 1)]
    with open(path, 'wb') as f:
        f.write(b'terrain of concave_test.py'.ljust(80, b' '))
        f.write(struct.pack('<I', 2 * n * n))
        for i in range(n):
            for j in range(n):
                a, b, c, d = corner[i][j], corner[i + 1][j], corner[i + 1][j + 1], corner[i][j + 1]
                for tri in ((a, b, c), (a, c, d)):  # counter-clockwise from above
                    f.write(struct.pack('<3f', 0.0, 0.0, 1.0))
                    for vertex in tri:
                        f.write(struct.pack('<3f', *vertex))
                    f.write(struct.pack('<H', 0))


def random_quaternion(rng):
    """Uniform on the sphere of unit quaternions (Shoemake 1992)."""
    u1, u2, u3 = rng.random(), rng.random(), rng.random()
    a, b = math.sqrt(1.0 - u1), math.sqrt(u1)
    return Quaternion(a * math.sin(2 * math.pi * u2), a * math.cos(2 * math.pi * u2),
                      b * math.sin(2 * math.pi * u3), b * math.cos(2 * math.pi * u3))


def rotate(q, v):
    """v turned by the unit quaternion q."""
    w, x, y, z = q.w, q.x, q.y, q.z
    t = (2 * (y * v[2] - z * v[1]), 2 * (z * v[0] - x * v[2]), 2 * (x * v[1] - y * v[0]))
    return (v[0] + w * t[0] + y * t[2] - z * t[1], v[1] + w * t[1] + z * t[0] - x * t[2],
            v[2] + w * t[2] + x * t[1] - y * t[0])


class ConcaveTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.data = os.path.join(rospkg.RosPack().get_path(PKG), 'test', 'data')
        cls.urdf_dir = os.path.join(rospkg.RosPack().get_path(PKG), 'urdf')

    def setUp(self):
        self.spawn_service = service('spawn', Spawn)
        self.get_state = service('get_state', GetState)
        self.step_service = service('step', Step)
        self.delete = service('delete', Delete)
        self.time_step = service('get_physics', GetPhysics)().time_step

    def spawn(self, name, urdf='', urdf_path='', at=None, twist=None, is_static=False,
              friction=-1.0):
        request = SpawnRequest(name=name, urdf=urdf, urdf_path=urdf_path, pose=at or pose(0, 0, 0),
                               is_static=is_static, friction=friction, restitution=-1.0)
        if twist is not None:
            request.twist = twist
        result = self.spawn_service(request)
        self.assertTrue(result.success, result.message)
        return result

    def run_for(self, seconds):
        result = self.step_service(int(round(seconds / self.time_step)))
        self.assertTrue(result.success, result.message)

    def state(self, name):
        state = self.get_state(name)
        self.assertTrue(state.success, state.message)
        return state

    def check_mug_holds_a_ball(self, name, inner, floor, x):
        """A mug of test/data (outer radius 4 cm, 10 cm tall, 32 segments) and a
        cached second spawn of it, each holding a 2 cm ball dropped in."""
        mug = mesh_urdf(name, os.path.join(self.data, name + '.stl'))
        # Upright on the ground; the balls (radius 1 cm) above the cavities,
        # whose floor is `floor` above the mug's base.
        self.spawn(name, urdf=mug, at=pose(x, 5.0, 0.001))
        started = time.monotonic()
        self.spawn(name + '_again', urdf=mug, at=pose(x + 1.0, 5.0, 0.001))
        second = time.monotonic() - started
        rospy.loginfo('second spawn of the decomposed %s: %.1f ms', name, 1000 * second)
        self.assertLess(second, 0.05)
        for mug_name, mug_x in ((name, x), (name + '_again', x + 1.0)):
            self.spawn(mug_name + '_marble',
                       urdf=primitive_urdf('marble', '<sphere radius="0.01"/>'),
                       at=pose(mug_x + 0.003, 5.002, 0.07))
        self.run_for(2.0)
        # Each ball rests on its cavity floor: its centre one radius above
        # z = floor, inside the cavity wall. The pieces may raise the floor:
        # a floor piece's hull exceeds its part by at most 1 % of the mug's
        # volume V (max_concavity), so over a quarter of the cavity's floor
        # area A it rises at most 0.01 V / (A / 4). The mug's hull would
        # have held the ball on the rim's lid at z = 0.11.
        segments = 32
        area = 0.5 * segments * math.sin(2.0 * math.pi / segments)  # of a unit-radius 32-gon
        volume = area * (0.04 ** 2 * 0.10 - inner ** 2 * (0.10 - floor))
        floor_fill = 0.01 * volume / (area * inner ** 2 / 4.0)
        for mug_name in (name, name + '_again'):
            mug_position = self.state(mug_name).pose.position
            ball = self.state(mug_name + '_marble').pose.position
            self.assertAlmostEqual(0.0, mug_position.z, delta=CONTACT_SLOP)
            self.assertGreater(ball.z, floor + 0.01 - CONTACT_SLOP)
            self.assertLess(ball.z, floor + 0.01 + floor_fill)
            rospy.loginfo('ball in %s at z = %.5f m on the cavity floor (%.3f m, fill bound %.5f m)',
                          mug_name, ball.z, floor + 0.01, floor_fill)
            self.assertLess(math.hypot(ball.x - mug_position.x, ball.y - mug_position.y),
                            inner - 0.01 + 1e-6)
        for mug_name in (name, name + '_again'):
            self.delete(mug_name)
            self.delete(mug_name + '_marble')

    def test_mug_holds_a_ball_and_its_second_spawn_is_fast(self):
        # Walls 5 mm thick, a 1 cm floor.
        self.check_mug_holds_a_ball('mug', inner=0.035, floor=0.01, x=0.0)

    def test_thin_walled_mug_holds_a_ball(self):
        # Walls 4 mm thick, a 5 mm floor: volume 0.23 of its hull's.
        self.check_mug_holds_a_ball('mug_thin', inner=0.036, floor=0.005, x=3.0)

    def test_l_bracket_straddles_a_box_on_its_two_feet(self):
        # The L's profile (x, z) is extreme along (1, 1) at its legs' inner
        # tip corners (0.3, 0.05) and (0.05, 0.3), x + z = 0.35. Pitched by
        # 135 deg about y those point straight down: the L stands on them,
        # its corner up, its outer corner (the model origin) 0.35 / sqrt(2)
        # above the ground, the notch between the legs 0.25 / sqrt(2) high
        # at its apex and 0.354 m wide at the ground. A 10 cm box fits under
        # it (notch 0.127 m high 5 cm off centre); the L's hull would rest on
        # the box's top, 0.1 m higher.
        pitch = 0.75 * math.pi
        rest_height = 0.35 / math.sqrt(2.0)
        self.spawn('block', urdf=primitive_urdf('block', '<box size="0.1 0.1 0.1"/>'),
                   at=pose(0.0, 10.05, 0.05), is_static=True)
        self.spawn('bracket', urdf=mesh_urdf('bracket', os.path.join(self.data, 'l_bracket.stl')),
                   at=pose(0.0, 10.0, rest_height + 0.01, pitch))
        self.run_for(2.0)
        state = self.state('bracket')
        rospy.loginfo('bracket origin at z = %.5f m (analytic %.5f m), x = %.5f m, pitch %.5f rad',
                      state.pose.position.z, rest_height, state.pose.position.x,
                      2.0 * math.atan2(state.pose.orientation.y, state.pose.orientation.w))
        self.assertAlmostEqual(rest_height, state.pose.position.z, delta=CONTACT_SLOP)
        self.assertAlmostEqual(0.0, state.pose.position.x, delta=0.001)
        q = state.pose.orientation
        # Still turned about y only, by 135 deg.
        self.assertAlmostEqual(0.0, math.hypot(q.x, q.z), delta=1e-3)
        self.assertAlmostEqual(pitch, 2.0 * math.atan2(q.y, q.w), delta=2e-3)
        for name in ('block', 'bracket'):
            self.delete(name)

    def test_box_dropped_into_the_bin_rests_on_its_floor(self):
        # bin.urdf: the floor's top 5 mm above the underside; a 10 cm box
        # rests with its centre 5 cm above it.
        self.spawn('bin', urdf_path=os.path.join(self.urdf_dir, 'bin.urdf'),
                   at=pose(0.0, -5.0, 0.0))
        self.spawn('crate', urdf=primitive_urdf('crate', '<box size="0.1 0.1 0.1"/>'),
                   at=pose(0.02, -5.01, 0.3))
        self.run_for(2.0)
        crate_z = self.state('crate').pose.position.z
        rospy.loginfo('crate in the bin at z = %.5f m (analytic 0.055 m)', crate_z)
        self.assertAlmostEqual(0.005 + 0.05, crate_z, delta=0.001)
        for name in ('bin', 'crate'):
            self.delete(name)

    def test_boxes_rest_on_a_terrain(self):
        # 300 boxes of 10 cm and 0.5 kg (friction 0.6) dropped from 5 to 50 cm
        # (their centres 9 cm more, above the reach of any corner) over a
        # 100,352-triangle terrain, in random orientations: after 5 s
        # every one rests on the surface. The lowest corner of each lies on
        # the triangle under it to within 5 mm, and none is below it by more
        # than the contact slop. A box that went through the terrain would
        # end on the ground plane, 0.48 m down.
        terrain_x, terrain_y = 30.0, 30.0
        with tempfile.TemporaryDirectory() as directory:
            path = os.path.join(directory, 'terrain.stl')
            write_terrain_stl(path)
            self.spawn('terrain', urdf=mesh_urdf('terrain', path),
                       at=pose(terrain_x, terrain_y, 0.0), is_static=True)
        inertia = 0.5 * 0.1 ** 2 / 6.0
        box = ('<robot name="box"><link name="body"><inertial><mass value="0.5"/>'
               '<inertia ixx="%g" iyy="%g" izz="%g" ixy="0" ixz="0" iyz="0"/></inertial>'
               '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'
               '</link></robot>' % (inertia, inertia, inertia))
        # One box in each of 300 of the 18 x 18 cells of 0.52 m, placed at
        # random within 0.16 m of the cell's centre, so no box lands on
        # another (which would rest a box's height above the terrain).
        rng = random.Random(39)
        names = []
        cell = 9.36 / 18
        for k, index in enumerate(sorted(rng.sample(range(18 * 18), 300))):
            x = -4.68 + (index // 18 + 0.5) * cell + rng.uniform(-0.16, 0.16)
            y = -4.68 + (index % 18 + 0.5) * cell + rng.uniform(-0.16, 0.16)
            z = terrain_height(x, y) + 0.09 + rng.uniform(0.05, 0.5)
            at = Pose(Point(terrain_x + x, terrain_y + y, z), random_quaternion(rng))
            names.append('terrain_box_%d' % k)
            self.spawn(names[-1], urdf=box, at=at, friction=0.6)
        self.run_for(5.0)
        corners = [(sx * 0.05, sy * 0.05, sz * 0.05)
                   for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]
        deepest, highest, fastest, fastest_turn = math.inf, -math.inf, 0.0, 0.0
        for name in names:
            state = self.state(name)
            p, q = state.pose.position, state.pose.orientation
            gaps = []
            for corner in corners:
                c = rotate(q, corner)
                cx, cy, cz = p.x + c[0] - terrain_x, p.y + c[1] - terrain_y, p.z + c[2]
                gaps.append(cz - terrain_height(cx, cy))
            lowest = min(gaps)
            deepest, highest = min(deepest, lowest), max(highest, lowest)
            v, w = state.twist.linear, state.twist.angular
            fastest = max(fastest, math.sqrt(v.x ** 2 + v.y ** 2 + v.z ** 2))
            fastest_turn = max(fastest_turn, math.sqrt(w.x ** 2 + w.y ** 2 + w.z ** 2))
            self.assertGreater(lowest, -CONTACT_SLOP, name)
            self.assertLess(lowest, 0.005, name)
        rospy.loginfo('300 boxes on the terrain after 5 s: lowest corners %.5f to %.5f m from the '
                      'surface, fastest %.2e m/s, %.2e rad/s', deepest, highest, fastest,
                      fastest_turn)
        # At rest: every box asleep, its velocity exactly zero.
        self.assertEqual(0.0, fastest)
        self.assertEqual(0.0, fastest_turn)
        for name in names + ['terrain']:
            self.delete(name)

    def test_ball_rolls_under_the_mesh_table(self):
        # mesh_table.urdf: a 1.0 x 0.8 m top from z = 0.27 m, legs at the
        # corners, so a 5 cm ball rolled along x between the legs passes
        # under it. Launched sliding at v0 = 1 m/s without spin, friction
        # mu = sqrt(0.5 * 0.8) (the default and the ground's, combined as the
        # geometric mean) brings it to rolling at 5/7 v0 after
        # t_s = 2 v0 / (7 mu g); by time t it has covered 5/7 v0 t + v0 t_s / 7.
        self.spawn('table', urdf_path=os.path.join(self.urdf_dir, 'mesh_table.urdf'),
                   at=pose(5.0, 0.0, 0.0))
        self.spawn('rolling_ball', urdf=primitive_urdf('rolling_ball', '<sphere radius="0.025"/>'),
                   at=pose(5.0 - 0.8, 0.0, 0.025), twist=Twist(Vector3(1.0, 0.0, 0.0), Vector3()))
        self.run_for(2.5)
        ball = self.state('rolling_ball').pose.position
        travelled = ball.x - (5.0 - 0.8)
        rolling_speed = 5.0 / 7.0
        slip_time = 2.0 / (7.0 * math.sqrt(0.5 * 0.8) * GRAVITY)
        rospy.loginfo('ball rolled %.5f m under the table (analytic %.5f m), now at x = %.4f',
                      travelled, rolling_speed * 2.5 + slip_time / 7.0, ball.x)
        self.assertAlmostEqual(rolling_speed * 2.5 + slip_time / 7.0, travelled, delta=0.003)
        self.assertGreater(ball.x, 5.0 + 0.5 + 0.025)  # out past the table's far edge
        self.assertAlmostEqual(0.0, ball.y, delta=0.001)
        self.assertAlmostEqual(0.025, ball.z, delta=CONTACT_SLOP)
        for name in ('table', 'rolling_ball'):
            self.delete(name)


if __name__ == '__main__':
    import rostest
    rospy.init_node('concave_test', anonymous=True)
    rostest.rosrun(PKG, 'concave', ConcaveTest)
