#!/usr/bin/env python3
"""The soft step through the node: ~solver/method soft_step at start-up, a
box dropped on the ground rests at its half height carrying its weight, a
landing is reported as a colliding contact, and dynamic_reconfigure
switches solvers at run time or refuses a name that is not one.

Run by soft_step_test.test: the node starts paused, with the soft step.
"""

import math
import threading
import time
import unittest

import rospy
from dynamic_reconfigure.client import Client
from rigid_body_sim.msg import Contacts
from rigid_body_sim.srv import Delete, GetState, Spawn, SpawnRequest, Step
from std_srvs.srv import SetBool

PKG = 'rigid_body_sim'
NODE = '/rigid_body_sim'
G = 9.81

BOX = ('<robot name="box"><link name="base_link"><inertial><mass value="2"/>'
       '<inertia ixx="0.0133" iyy="0.0133" izz="0.0133" ixy="0" ixz="0" iyz="0"/></inertial>'
       '<collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision></link></robot>')


def service(name, service_type):
    rospy.wait_for_service(NODE + '/' + name, timeout=30)
    return rospy.ServiceProxy(NODE + '/' + name, service_type)


class SoftStepTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.step = service('step', Step)
        cls.spawn = service('spawn', Spawn)
        cls.delete = service('delete', Delete)
        cls.get_state = service('get_state', GetState)
        service('set_paused', SetBool)(True)
        cls.client = Client(NODE, timeout=30)
        cls.lock = threading.Lock()
        cls.contacts = []

        def on_contacts(message):
            with cls.lock:
                cls.contacts.append(message)
        cls.subscriber = rospy.Subscriber(NODE + '/contacts', Contacts, on_contacts)
        # Paused, the node publishes after each ~step call only: connect first.
        deadline = time.monotonic() + 30.0
        while cls.subscriber.get_num_connections() == 0 and time.monotonic() < deadline:
            time.sleep(0.05)

    def drop_box(self, name, height):
        request = SpawnRequest(name=name, urdf=BOX, friction=-1.0, restitution=-1.0)
        request.pose.position.z = 0.1 + height
        request.pose.orientation.w = 1.0
        response = self.spawn(request)
        self.assertTrue(response.success, response.message)

    def box_contacts(self, name):
        """(colliding, resting) contacts of the box in the messages so far."""
        with self.lock:
            messages = list(self.contacts)
        colliding = []
        resting = []
        for message in messages:
            for contact in message.contacts:
                if name + '/base_link' not in (contact.body_a, contact.body_b):
                    continue
                (colliding if contact.type == contact.COLLIDING else resting).append(contact)
        return colliding, resting

    def test_started_with_the_soft_step(self):
        self.assertEqual('soft_step', self.client.get_configuration(timeout=30)['solver_method'])
        # Restored for the other tests, whatever a test left.
        self.client.update_configuration({'solver_method': 'soft_step'})

    def test_dropped_box_lands_colliding_and_rests_carrying_its_weight(self):
        drop = 0.5
        self.drop_box('soft_box', drop)
        with self.lock:
            del self.contacts[:]  # the class's list, which the callback fills
        # 0.32 s to fall 0.5 m; 0.4 s more to settle, still awake.
        self.step(172)
        time.sleep(0.5)
        state = self.get_state('soft_box')
        self.assertTrue(state.success, state.message)
        self.assertAlmostEqual(0.1, state.pose.position.z, delta=1e-3)
        colliding, _ = self.box_contacts('soft_box')
        self.assertTrue(colliding, 'no colliding contact reported for the landing')
        speed = math.sqrt(2.0 * G * drop)
        # Every corner closes at the fall speed, within two sub-steps'
        # gravity (the sub-step it closes in, and symplectic Euler's lead).
        landing = [c for c in colliding if c.normal_velocity < -1.0]
        self.assertEqual(4, len(landing), [c.normal_velocity for c in colliding])
        for contact in landing:
            self.assertAlmostEqual(-speed, contact.normal_velocity, delta=2.0 * G / 960.0)
        with self.lock:
            last = self.contacts[-1]
        # The message also carries every colliding contact since the last
        # one; the last step's are the resting ones.
        weight = sum(c.normal_force * abs(c.normal.z) for c in last.contacts
                     if 'soft_box/base_link' in (c.body_a, c.body_b) and c.type == c.RESTING)
        self.assertAlmostEqual(2.0 * G, weight, delta=0.01 * 2.0 * G)
        self.assertTrue(self.delete('soft_box').success)

    def test_solver_switches_at_run_time_and_refuses_a_bad_name(self):
        # update_configuration returns the configuration the node ended with.
        self.assertEqual('exact',
                         self.client.update_configuration({'solver_method': 'exact'})[
                             'solver_method'])
        self.drop_box('switch_box', 0.0)
        self.step(120)
        self.assertEqual('soft_step',
                         self.client.update_configuration({'solver_method': 'soft_step'})[
                             'solver_method'])
        self.step(120)
        state = self.get_state('switch_box')
        self.assertAlmostEqual(0.1, state.pose.position.z, delta=1e-4)
        self.assertLess(abs(state.twist.linear.z), 1e-3)
        refused = self.client.update_configuration({'solver_method': 'pgs'})
        self.assertEqual('soft_step', refused['solver_method'])
        self.assertTrue(self.delete('switch_box').success)


if __name__ == '__main__':
    import rostest
    rospy.init_node('soft_step_test')
    rostest.rosrun(PKG, 'soft_step', SoftStepTest)
