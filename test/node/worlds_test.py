#!/usr/bin/env python3
"""The shipped worlds, loaded by `sim.launch world:=<name>` and run flat out:
every model is there and settles where physics puts it.

Run by worlds_table_top_test.test and worlds_bin_test.test, which set ~world.
"""

import time
import unittest

import rospy
from rigid_body_sim.srv import GetModelProperties, GetState, GetWorldProperties

PKG = 'rigid_body_sim'
SIM = '/rigid_body_sim/'
SETTLE_SIM_TIME = 5.0  # s of sim time for everything to come to rest
TOP = 0.75  # m, the table top's upper face
MARGIN = 0.005  # m: contact margin and the solver's slop


def service(name, service_type):
    rospy.wait_for_service(SIM + name, timeout=60)
    return rospy.ServiceProxy(SIM + name, service_type)


class WorldsTest(unittest.TestCase):

    def setUp(self):
        self.world = service('get_world_properties', GetWorldProperties)
        self.get_state = service('get_state', GetState)
        self.model = service('get_model_properties', GetModelProperties)
        deadline = time.monotonic() + 120.0
        while self.world().sim_time < SETTLE_SIM_TIME and time.monotonic() < deadline:
            time.sleep(0.1)
        self.assertGreaterEqual(self.world().sim_time, SETTLE_SIM_TIME)

    def position(self, name):
        state = self.get_state(name)
        self.assertTrue(state.success, state.message)
        return state.pose.position

    def test_world(self):
        getattr(self, 'check_' + rospy.get_param('~world'))()

    def check_table_top(self):
        self.assertEqual(['ball', 'book', 'can', 'crate', 'table'],
                         list(self.world().model_names))
        self.assertTrue(self.model('table').is_static)
        self.assertEqual([0.2], list(self.model('book').link_masses))  # the inline URDF's
        # Each rests on the top: its centre half its height above it.
        for name, half_height in (('crate', 0.15), ('ball', 0.1), ('can', 0.1),
                                  ('book', 0.015)):
            self.assertAlmostEqual(TOP + half_height, self.position(name).z, delta=MARGIN,
                                   msg=name)

    def check_bin(self):
        names = list(self.world().model_names)
        self.assertEqual(['ball_a', 'ball_b', 'bin', 'can_a', 'crate_a', 'crate_b', 'pebble'],
                         names)
        self.assertTrue(self.model('bin').is_static)
        # Everything fell inside: within the walls' inner faces (+-0.45 m),
        # above the floor's top (0.05 m), below the walls' top (0.55 m).
        for name in names:
            if name == 'bin':
                continue
            p = self.position(name)
            self.assertLess(abs(p.x), 0.45, name)
            self.assertLess(abs(p.y), 0.45, name)
            self.assertGreater(p.z, 0.05, name)
            self.assertLess(p.z, 0.55, name)


if __name__ == '__main__':
    import rostest
    rospy.init_node('worlds_test', anonymous=True)
    rostest.rosrun(PKG, 'worlds', WorldsTest)
