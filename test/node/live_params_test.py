#!/usr/bin/env python3
"""Live parameters: dynamic_reconfigure (dynparam, the Python client) and
~set_physics change the running node, within the ranges of cfg/Physics.cfg.

Run by live_params_test.test: the node starts paused, under wall time.
"""

import subprocess
import threading
import time
import unittest

import rospy
from dynamic_reconfigure.client import Client
from geometry_msgs.msg import Vector3
from rigid_body_sim.msg import ModelStates
from rigid_body_sim.srv import (GetPhysics, GetState, SetPhysics, SetPhysicsRequest, Spawn,
                                SpawnRequest, Step)
from rosgraph_msgs.msg import Log
from std_srvs.srv import SetBool

PKG = 'rigid_body_sim'
NODE = '/rigid_body_sim'
DEFAULT_TIME_STEP = 1.0 / 240.0

BALL = ('<robot name="ball"><link name="base_link"><inertial><mass value="1"/>'
        '<inertia ixx="0.004" iyy="0.004" izz="0.004" ixy="0" ixz="0" iyz="0"/></inertial>'
        '<collision><geometry><sphere radius="0.1"/></geometry></collision></link></robot>')


def service(name, service_type):
    rospy.wait_for_service(NODE + '/' + name, timeout=30)
    return rospy.ServiceProxy(NODE + '/' + name, service_type)


def dynparam(*args):
    """`rosrun dynamic_reconfigure dynparam ARGS`; (exit status, output)."""
    process = subprocess.run(['rosrun', 'dynamic_reconfigure', 'dynparam'] + list(args),
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             universal_newlines=True, timeout=60)
    return process.returncode, process.stdout


class LiveParamsTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.warnings = []
        cls.lock = threading.Lock()

        def on_log(message):
            if message.name == NODE and message.level == Log.WARN:
                with cls.lock:
                    cls.warnings.append(message.msg)
        cls.rosout = rospy.Subscriber('/rosout', Log, on_log)
        cls.get_physics = service('get_physics', GetPhysics)
        cls.set_physics = service('set_physics', SetPhysics)
        cls.step = service('step', Step)
        service('set_paused', SetBool)(True)
        cls.client = Client(NODE, timeout=30)

    def tearDown(self):
        # Back to the shipped values for the next test.
        self.client.update_configuration({
            'time_step': DEFAULT_TIME_STEP, 'gravity_x': 0.0, 'gravity_y': 0.0,
            'gravity_z': -9.81, 'publish_rate': 50.0, 'real_time_factor': 1.0})

    def wait_for_warning(self, fragment, timeout=10.0):
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            with self.lock:
                if any(fragment in warning for warning in self.warnings):
                    return True
            time.sleep(0.05)
        with self.lock:
            self.fail('no WARN from the node containing %r; got %r' % (fragment, self.warnings))

    def test_dynparam_time_step_takes_effect(self):
        status, output = dynparam('set', NODE, 'time_step', '0.002')
        self.assertEqual(0, status, output)
        self.assertEqual(0.002, self.get_physics().time_step)
        self.assertEqual(0.002, rospy.get_param(NODE + '/time_step'))
        before = self.step(0).sim_time
        after = self.step(100).sim_time
        self.assertAlmostEqual(100 * 0.002, after - before, delta=1e-12)

    def test_dynparam_time_step_5_is_clamped_to_the_maximum_with_a_warning(self):
        status, output = dynparam('set', NODE, 'time_step', '5')
        self.assertEqual(0, status, output)
        self.assertEqual(0.1, self.get_physics().time_step)
        self.wait_for_warning('time_step 0.1 s is above 1/30 s')
        self.wait_for_warning('dynamic_reconfigure clamps larger values to it')

    def test_set_physics_refuses_half_a_second_and_changes_nothing(self):
        request = SetPhysicsRequest(gravity=Vector3(0.0, 0.0, -1.0), keep_gravity=False,
                                    time_step=0.5, real_time_factor=2.0)
        response = self.set_physics(request)
        self.assertFalse(response.success)
        self.assertEqual('time_step 0.5 s is outside [1e-05, 0.1] s', response.message)
        physics = self.get_physics()
        self.assertEqual(DEFAULT_TIME_STEP, physics.time_step)
        self.assertEqual(-9.81, physics.gravity.z)
        self.assertEqual(1.0, physics.real_time_factor)

    def test_set_physics_fields_are_optional_and_reach_dynamic_reconfigure(self):
        keep_all = SetPhysicsRequest(keep_gravity=True, time_step=0.0, real_time_factor=-1.0)
        self.assertTrue(self.set_physics(keep_all).success)
        physics = self.get_physics()
        self.assertEqual((0.0, 0.0, -9.81, DEFAULT_TIME_STEP, 1.0),
                         (physics.gravity.x, physics.gravity.y, physics.gravity.z,
                          physics.time_step, physics.real_time_factor))
        coarse = SetPhysicsRequest(keep_gravity=True, time_step=0.05, real_time_factor=-1.0)
        response = self.set_physics(coarse)
        self.assertTrue(response.success, response.message)
        self.assertIn('warning: time_step 0.05 s is above 1/30 s', response.message)
        self.assertEqual(0.05, self.get_physics().time_step)
        self.assertEqual(-9.81, self.get_physics().gravity.z)
        # The server has it before the reply (its parameter is written then);
        # a client hears it on ~parameter_updates shortly after.
        self.assertEqual(0.05, rospy.get_param(NODE + '/time_step'))
        deadline = time.monotonic() + 10.0
        while (self.client.get_configuration(timeout=10)['time_step'] != 0.05 and
               time.monotonic() < deadline):
            time.sleep(0.05)
        self.assertEqual(0.05, self.client.get_configuration(timeout=10)['time_step'])

    def test_gravity_is_live(self):
        spawn = SpawnRequest(name='moon_ball', urdf=BALL, friction=-1.0, restitution=-1.0)
        spawn.pose.position.z = 50.0
        spawn.pose.orientation.w = 1.0
        self.assertTrue(service('spawn', Spawn)(spawn).success)
        self.client.update_configuration({'gravity_z': -1.62})
        self.assertEqual(-1.62, self.get_physics().gravity.z)
        self.step(240)
        # Free fall from rest: v = g t after 240 steps of 1/240 s.
        velocity = service('get_state', GetState)('moon_ball').twist.linear.z
        self.assertAlmostEqual(-1.62, velocity, delta=1e-9)

    def test_publish_rate_is_live(self):
        self.client.update_configuration({'publish_rate': 5.0})
        count = [0]

        def on_states(_):
            count[0] += 1
        subscriber = rospy.Subscriber(NODE + '/states', ModelStates, on_states)
        time.sleep(1.0)  # connect, and let the old schedule go
        count[0] = 0
        time.sleep(4.0)
        subscriber.unregister()
        # 5 Hz for 4 s of wall time, give or take a message at either end.
        self.assertGreaterEqual(count[0], 19)
        self.assertLessEqual(count[0], 21)


if __name__ == '__main__':
    import rostest
    rospy.init_node('live_params_test', anonymous=True)
    rostest.rosrun(PKG, 'live_params', LiveParamsTest)
