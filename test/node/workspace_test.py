#!/usr/bin/env python3
"""A robot workspace as a Gazebo user runs it, through the node's ROS
interface: an arm spawned with robot namespace '/' and tf of its root link
only, beside robot_state_publisher fed from /joint_states, gives one
connected tf tree whose every frame is where the node's own link poses say."""
import math
import sys
import time
import unittest

import rospkg
import rospy
import rostest
import tf2_ros
import yaml
from geometry_msgs.msg import Pose
from rigid_body_sim.srv import (Delete, GetModelProperties, GetState, Spawn, SpawnRequest,
                                Step)
from sensor_msgs.msg import JointState

PKG = 'rigid_body_sim'
SIM = '/rigid_body_sim/'
LINKS = ['link%d' % i for i in range(8)]


def service(name, kind):
    rospy.wait_for_service(SIM + name, timeout=30.0)
    return rospy.ServiceProxy(SIM + name, kind, persistent=True)


class WorkspaceTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.package = rospkg.RosPack().get_path(PKG)
        cls.spawn = service('spawn', Spawn)
        cls.delete = service('delete', Delete)
        cls.step = service('step', Step)
        cls.get_state = service('get_state', GetState)

    def test_robot_state_publisher_completes_one_tree(self):
        joints = ['joint%d' % (i + 1) for i in range(7)]
        pose = [0.3, -0.5, 0.2, -1.8, 0.1, 1.4, 0.5]
        # Its base fixed where it is spawned (is_static keeps the joints).
        # No tf_prefix: in root mode the frames are the URDF's own names.
        request = SpawnRequest(name='panda_like', robot_namespace='/', tf_mode='root',
                               hold=True, is_static=True, friction=-1.0, restitution=-1.0)
        request.urdf_path = self.package + '/test/data/seven_dof_arm_free.urdf'
        request.pose = Pose()
        request.pose.position.x, request.pose.position.y = 0.4, 1.2
        request.pose.orientation.z = math.sin(0.3)
        request.pose.orientation.w = math.cos(0.3)
        request.joint_names = joints
        request.joint_positions = pose
        response = self.spawn(request)
        self.assertTrue(response.success, response.message)
        self.addCleanup(self.delete, 'panda_like')
        self.assertEqual(['link0', 'link1'], list(response.frames)[:2])

        # The global /joint_states, where robot_state_publisher reads it.
        states = rospy.wait_for_message('/joint_states', JointState, timeout=20.0)
        self.assertEqual(joints, list(states.name))
        # Under sim time the node sends tf only when time moves: listen first.
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        self.assertIsNotNone(listener)
        time.sleep(1.0)  # wall time: sim time stands still while paused
        # Held at the spawn positions (hold), so the poses below stay put.
        self.step(240)
        time.sleep(1.0)
        for link in LINKS:
            transform = buffer.lookup_transform('world', link, rospy.Time(0),
                                                rospy.Duration(20.0)).transform
            expected = self.get_state('panda_like/' + link).pose
            for axis in 'xyz':
                self.assertAlmostEqual(getattr(expected.position, axis),
                                       getattr(transform.translation, axis), delta=1e-6,
                                       msg=link + ' ' + axis)
            for axis in 'xyzw':
                self.assertAlmostEqual(abs(getattr(expected.orientation, axis)),
                                       abs(getattr(transform.rotation, axis)), delta=1e-6,
                                       msg=link + ' q' + axis)
        # One tree: the node gives world -> base only, robot_state_publisher
        # the rest, and no frame is published twice under two names.
        frames = yaml.safe_load(buffer.all_frames_as_yaml())
        self.assertEqual('world', frames['link0']['parent'])
        self.assertEqual('link6', frames['link7']['parent'])
        self.assertFalse(any(name.startswith('panda_like/') for name in frames))

    def test_xacro_spawns_as_its_hand_expanded_urdf(self):
        # A description written as the published ones are (macros, includes
        # through $(find), args, YAML limits), spawned by path with
        # xacro_args, is the model its hand-expanded URDF gives, link for
        # link and joint for joint; the reply names what is not simulated.
        properties = service('get_model_properties', GetModelProperties)
        data = self.package + '/test/data/xacro/'
        spawned = []
        for name, path, args in (
                ('from_xacro', data + 'packages/fake_arm_description/urdf/two_link_arm.urdf.xacro',
                 ['gazebo:=true']),
                ('by_hand', data + 'expected/two_link_arm.urdf', [])):
            request = SpawnRequest(name=name, urdf_path=path, xacro_args=args, is_static=True,
                                   friction=-1.0, restitution=-1.0)
            request.pose.orientation.w = 1.0
            response = self.spawn(request)
            self.assertTrue(response.success, response.message)
            self.addCleanup(self.delete, name)
            spawned.append((response, properties(name)))
        (xacro_reply, xacro_model), (hand_reply, hand_model) = spawned
        self.assertEqual([f.split('/', 1)[1] for f in hand_reply.frames],
                         [f.split('/', 1)[1] for f in xacro_reply.frames])
        self.assertEqual(list(hand_model.link_names), list(xacro_model.link_names))
        self.assertEqual(list(hand_model.joint_names), list(xacro_model.joint_names))
        self.assertEqual(list(hand_model.joint_types), list(xacro_model.joint_types))
        for hand, made in zip(hand_model.link_masses, xacro_model.link_masses):
            self.assertAlmostEqual(hand, made, delta=1e-12)
        self.assertIn('ignored (not simulated): <transmission', xacro_reply.message)
        # An expression the description cannot evaluate is refused naming
        # the file, the line and the construct.
        request = SpawnRequest(name='broken', friction=-1.0, restitution=-1.0,
                               urdf="<robot name='b' xmlns:xacro='http://www.ros.org/wiki/xacro'>"
                                    "<link name='l'><collision><geometry>"
                                    "<box size='${s * 2} 1 1'/></geometry></collision></link>"
                                    "</robot>")
        request.pose.orientation.w = 1.0
        response = self.spawn(request)
        self.assertFalse(response.success)
        self.assertIn('xacro', response.message)
        self.assertIn(':1: ', response.message)
        self.assertIn("'s'", response.message)

    def test_namespace_is_taken_once(self):
        request = SpawnRequest(name='first', robot_namespace='robots/left', friction=-1.0,
                               restitution=-1.0)
        request.urdf_path = self.package + '/test/data/two_link_arm.urdf'
        request.pose.orientation.w = 1.0
        request.pose.position.z = 1.5
        response = self.spawn(request)
        self.assertTrue(response.success, response.message)
        self.addCleanup(self.delete, 'first')
        message = rospy.wait_for_message('/robots/left/joint_states', JointState, timeout=20.0)
        self.assertEqual(['shoulder', 'elbow'], list(message.name))
        request.name = 'second'
        response = self.spawn(request)
        self.assertFalse(response.success)
        self.assertIn("robot_namespace '/robots/left' is taken by model 'first'", response.message)
        for bad in ('1robot', 'a b', 'ok/-x'):
            request.robot_namespace = bad
            response = self.spawn(request)
            self.assertFalse(response.success)
            self.assertIn('robot_namespace', response.message)


if __name__ == '__main__':
    rospy.init_node('workspace_test')
    rostest.rosrun(PKG, 'workspace', WorkspaceTest, sys.argv)
