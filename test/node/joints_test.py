#!/usr/bin/env python3
"""Articulated models through the ROS interface: joint_states, joint_command,
joint_trajectory, ~set_joint_state, ~reset, tf, a link's impact, against closed forms.

Run by joints_test.test: the node starts paused with its ground plane; every
test spawns models of its own and steps the world with ~step.
"""

import math
import threading
import unittest

import rospkg
import yaml
import rospy
import tf2_ros
from geometry_msgs.msg import Pose
from rigid_body_sim.srv import (Delete, GetState, SetJointState, SetJointStateRequest, Spawn,
                                SpawnRequest, Step)
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger
from trajectory_msgs.msg import JointTrajectory, JointTrajectoryPoint

PKG = 'rigid_body_sim'
SIM = '/rigid_body_sim/'
G = 9.81
DT = 1.0 / 240.0

# A 1 kg ball of radius 0.01 m on a massless 1 m arm, hinged about z at the
# spawn pose, fixed to 'world'.
STRIKER_URDF = """<robot name="striker">
  <link name="world"/>
  <joint name="mount" type="fixed"><parent link="world"/><child link="pivot"/></joint>
  <link name="pivot">
    <inertial><mass value="0.1"/>
      <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
  </link>
  <joint name="hinge" type="continuous">
    <parent link="pivot"/><child link="arm"/><axis xyz="0 0 1"/>
  </joint>
  <link name="arm">
    <inertial><origin xyz="1 0 0"/><mass value="1"/>
      <inertia ixx="1e-4" iyy="1e-4" izz="1e-4" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="1 0 0"/><geometry><sphere radius="0.01"/></geometry></collision>
  </link>
</robot>"""

# A 0.2 m box of 1 kg.
BOX_URDF = """<robot name="box">
  <link name="box">
    <inertial><mass value="1"/>
      <inertia ixx="0.00667" iyy="0.00667" izz="0.00667" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.2"/></geometry></collision>
  </link>
</robot>"""


def service(name, service_type):
    rospy.wait_for_service(SIM + name, timeout=30)
    return rospy.ServiceProxy(SIM + name, service_type)


def elliptic_k(k):
    """K(k) by the arithmetic-geometric mean (Abramowitz and Stegun 17.6)."""
    a, b = 1.0, math.sqrt(1.0 - k * k)
    for _ in range(40):
        a, b = 0.5 * (a + b), math.sqrt(a * b)
    return math.pi / (2.0 * a)


class Latest:
    """The latest message of a topic, and a way to wait for a newer one."""

    def __init__(self, topic, message_type):
        self.message = None
        self.count = 0
        self.condition = threading.Condition()
        self.subscriber = rospy.Subscriber(topic, message_type, self.callback)

    def callback(self, message):
        with self.condition:
            self.message = message
            self.count += 1
            self.condition.notify_all()

    def newer(self, timeout=10.0):
        with self.condition:
            start = self.count
            self.condition.wait_for(lambda: self.count > start, timeout)
            return self.message


class JointsTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.package = rospkg.RosPack().get_path(PKG)
        cls.spawn = service('spawn', Spawn)
        cls.delete = service('delete', Delete)
        cls.step = service('step', Step)
        cls.get_state = service('get_state', GetState)
        cls.set_joint_state = service('set_joint_state', SetJointState)
        cls.reset = service('reset', Trigger)

    def spawn_urdf(self, name, urdf, z, joints=None, x=0.0):
        request = SpawnRequest()
        request.name = name
        request.urdf_path = self.package + '/test/data/' + urdf
        request.pose = Pose()
        request.pose.position.x = x
        request.pose.position.z = z
        request.pose.orientation.w = 1.0
        request.friction = -1.0
        request.restitution = -1.0
        for joint, position in (joints or {}).items():
            request.joint_names.append(joint)
            request.joint_positions.append(position)
        response = self.spawn(request)
        self.assertTrue(response.success, response.message)
        self.addCleanup(self.delete, name)
        return response

    def joint_states(self, model):
        """A joint_states message stamped after the last step."""
        latest = Latest(SIM + model + '/joint_states', JointState)
        try:
            for _ in range(3):
                message = latest.newer()
                if message is not None:
                    return message
            self.fail('no joint_states from ' + model)
        finally:
            latest.subscriber.unregister()

    def command(self, model, **fields):
        publisher = rospy.Publisher(SIM + model + '/joint_command', JointState, queue_size=1,
                                    latch=True)
        message = JointState()
        for key, value in fields.items():
            setattr(message, key, value)
        publisher.publish(message)
        rospy.sleep(0.5)  # delivered before the next step
        return publisher

    def test_pendulum_period_matches_the_elliptic_integral(self):
        amplitude = math.radians(45.0)
        self.spawn_urdf('pendulum', 'pendulum.urdf', 3.0, {'hinge': amplitude})
        crossings = []
        previous = amplitude
        for step in range(1, 2000):
            self.step(1)
            pose = self.get_state('pendulum/bob').pose.orientation
            angle = 2.0 * math.atan2(pose.y, pose.w)
            if previous < 0.0 <= angle:
                crossings.append((step - 1 + previous / (previous - angle)) * DT)
            previous = angle
            if len(crossings) == 2:
                break
        self.assertEqual(2, len(crossings))
        inertia = 4e-5 + 1.0
        expected = 4.0 * math.sqrt(inertia / (G * 1.0)) * elliptic_k(math.sin(amplitude / 2))
        self.assertAlmostEqual(1.0, (crossings[1] - crossings[0]) / expected, delta=1e-5)

    def test_joint_states_follow_the_urdf_and_commands_hold(self):
        self.spawn_urdf('arm', 'two_link_arm.urdf', 1.5, {'shoulder': 0.4, 'elbow': -0.3})
        states = self.joint_states('arm')
        self.assertEqual(['shoulder', 'elbow'], list(states.name))
        self.assertAlmostEqual(0.4, states.position[0], delta=1e-12)
        self.assertAlmostEqual(-0.3, states.position[1], delta=1e-12)

        # A command naming an unknown joint is refused whole.
        self.command('arm', name=['shoulder', 'wrist'], position=[1.0, 1.0])
        self.command('arm', name=['shoulder', 'elbow'], position=[0.4, -0.3])
        self.step(5 * 240)
        states = self.joint_states('arm')
        # The servo's steady error is the gravity torque over its stiffness
        # (1e5 N m/rad): below 1e-4 rad for this arm.
        self.assertAlmostEqual(0.4, states.position[0], delta=1e-4)
        self.assertAlmostEqual(-0.3, states.position[1], delta=1e-4)

        self.command('arm', name=['elbow'], velocity=[0.5])
        self.step(120)
        self.assertAlmostEqual(0.5, self.joint_states('arm').velocity[1], delta=5e-3)

    def test_set_joint_state_and_reset(self):
        self.spawn_urdf('arm2', 'two_link_arm.urdf', 1.5, {'elbow': 0.2})
        request = SetJointStateRequest(model='arm2', joint_names=['shoulder'], positions=[1.0])
        response = self.set_joint_state(request)
        self.assertTrue(response.success, response.message)
        states = self.joint_states('arm2')
        self.assertAlmostEqual(1.0, states.position[0], delta=1e-12)
        self.assertAlmostEqual(0.2, states.position[1], delta=1e-12)
        for bad in (SetJointStateRequest(model='arm2', joint_names=['wrist'], positions=[0.0]),
                    SetJointStateRequest(model='arm2', joint_names=['elbow'], positions=[3.0]),
                    SetJointStateRequest(model='arm2', joint_names=['elbow'], positions=[])):
            self.assertFalse(self.set_joint_state(bad).success)
        self.assertAlmostEqual(0.2, self.joint_states('arm2').position[1], delta=1e-12)
        self.step(48)
        self.assertTrue(self.reset().success)
        states = self.joint_states('arm2')
        self.assertAlmostEqual(0.0, states.position[0], delta=1e-12)
        self.assertAlmostEqual(0.2, states.position[1], delta=1e-12)

    def test_hostile_joint_values_are_refused_by_name(self):
        """Joint values beyond the request limits (README) are refused, naming the joint,
        the field and the value, and change nothing."""
        request = SpawnRequest(name='arm4', friction=-1.0, restitution=-1.0,
                               urdf_path=self.package + '/test/data/two_link_arm.urdf',
                               joint_names=['shoulder'], joint_positions=[1e300])
        request.pose.position.z = 1.5
        request.pose.orientation.w = 1.0
        response = self.spawn(request)
        self.assertFalse(response.success)
        for word in ("joint_positions of 'shoulder'", '1e+300', '[-10000, 10000]'):
            self.assertIn(word, response.message)
        self.assertFalse(self.get_state('arm4').success)

        self.spawn_urdf('arm4', 'two_link_arm.urdf', 1.5, {'elbow': 0.2})
        for bad, words in (
                (SetJointStateRequest(model='arm4', joint_names=['elbow'], positions=[0.0],
                                      velocities=[1e300]),
                 ("joint 'elbow' velocity", '1e+300 rad/s', '[-10000, 10000] rad/s')),
                (SetJointStateRequest(model='arm4', joint_names=['elbow', 'elbow'],
                                      positions=[0.0, 0.1]),
                 ("joint_names[1] 'elbow'", 'given twice'))):
            response = self.set_joint_state(bad)
            self.assertFalse(response.success)
            for word in words:
                self.assertIn(word, response.message)
        self.assertAlmostEqual(0.2, self.joint_states('arm4').position[1], delta=1e-12)

        # Held by position servos, then a velocity beyond ~max_angular_speed
        # and a joint named twice: both refused whole, the servos keep holding.
        self.command('arm4', name=['shoulder', 'elbow'], position=[0.4, -0.3])
        self.command('arm4', name=['elbow'], velocity=[1e300])
        self.command('arm4', name=['shoulder', 'shoulder'], position=[1.0, 1.0])
        self.step(240)
        states = self.joint_states('arm4')
        self.assertAlmostEqual(0.4, states.position[0], delta=1e-4)
        self.assertAlmostEqual(-0.3, states.position[1], delta=1e-4)

    def test_massless_base_and_joint_to_world_are_fixed_bases(self):
        """Bullet's mass-0 root link, and a prismatic joint from 'world', fix the base where
        the model is spawned; a cart on a vertical rail falls as z0 - g t^2 / 2."""
        self.spawn_urdf('bullet_pendulum', 'massless_base_pendulum.urdf', 3.0, {'hinge': 0.5},
                        x=-4.0)
        self.spawn_urdf('pendulum_ref', 'pendulum.urdf', 3.0, {'hinge': 0.5}, x=4.0)
        self.spawn_urdf('rail', 'vertical_rail.urdf', 5.0, x=8.0)
        steps = 120
        self.step(steps)
        pivot = self.get_state('bullet_pendulum/pivot')
        self.assertTrue(pivot.success, pivot.message)
        self.assertAlmostEqual(3.0, pivot.pose.position.z, delta=1e-12)
        self.assertAlmostEqual(-4.0, pivot.pose.position.x, delta=1e-12)
        # It swings as pendulum.urdf does, whose base is fixed to 'world'.
        reference = self.joint_states('pendulum_ref')
        swung = self.joint_states('bullet_pendulum')
        self.assertEqual(['hinge'], list(swung.name))
        self.assertLess(swung.position[0], 0.45)
        self.assertAlmostEqual(reference.position[0], swung.position[0], delta=1e-12)
        self.assertAlmostEqual(reference.velocity[0], swung.velocity[0], delta=1e-12)
        t = steps * DT
        cart = self.get_state('rail/cart').pose.position
        self.assertAlmostEqual(5.0 - 0.5 * G * t * t, cart.z, delta=1e-9)
        self.assertAlmostEqual(8.0, cart.x, delta=1e-12)
        self.assertAlmostEqual(0.0, cart.y, delta=1e-12)

    def test_hinged_link_strikes_a_static_box_at_the_contact_time(self):
        """A 1 m arm on a hinge about z (gravity gives it no torque) swings its 1 cm ball into
        the face y = 0 of a static box at 3 m/s, e = 0.5: the impact step ends at
        theta_c - e omega (t - t_c), with theta_c = -asin(r / L) and t_c = 5.37 steps, and
        the arm leaves at -e omega to 1e-6 relative."""
        length, radius, restitution, speed, steps_to_impact = 1.0, 0.01, 0.5, 3.0, 5.37
        contact_angle = -math.asin(radius / length)
        omega = speed / (length * math.cos(contact_angle))
        start_angle = contact_angle - omega * steps_to_impact * DT
        striker = SpawnRequest()
        striker.name = 'striker'
        striker.urdf = STRIKER_URDF
        striker.pose.position.x = -6.0
        striker.pose.position.z = 1.0
        striker.pose.orientation.w = 1.0
        striker.friction = 0.0
        striker.restitution = restitution
        striker.joint_names = ['hinge']
        striker.joint_positions = [start_angle]
        response = self.spawn(striker)
        self.assertTrue(response.success, response.message)
        self.addCleanup(self.delete, 'striker')
        wall = SpawnRequest()
        wall.name = 'struck_box'
        wall.urdf = BOX_URDF
        wall.pose.position.x = -6.0 + length
        wall.pose.position.y = 0.1
        wall.pose.position.z = 1.0
        wall.pose.orientation.w = 1.0
        wall.is_static = True
        wall.friction = 0.0
        wall.restitution = restitution
        response = self.spawn(wall)
        self.assertTrue(response.success, response.message)
        self.addCleanup(self.delete, 'struck_box')
        request = SetJointStateRequest()
        request.name = 'striker'
        request.joint_names = ['hinge']
        request.positions = [start_angle]
        request.velocities = [omega]
        response = self.set_joint_state(request)
        self.assertTrue(response.success, response.message)

        def arm_angle_and_rate():
            state = self.get_state('striker/arm')
            self.assertTrue(state.success, state.message)
            rotation = state.pose.orientation
            return 2.0 * math.atan2(rotation.z, rotation.w), state.twist.angular.z

        steps = 0
        angle, rate = arm_angle_and_rate()
        while steps < 20 and rate > 0.0:
            self.step(1)
            steps += 1
            angle, rate = arm_angle_and_rate()
        self.assertEqual(6, steps)
        expected = contact_angle - restitution * omega * (steps * DT - steps_to_impact * DT)
        self.assertAlmostEqual(expected, angle, delta=1e-8)
        self.assertAlmostEqual(1.0, rate / (-restitution * omega), delta=1e-6)

    def test_trajectory_reaches_its_points_on_time(self):
        self.spawn_urdf('arm3', 'two_link_arm.urdf', 1.5)
        publisher = rospy.Publisher(SIM + 'arm3/joint_trajectory', JointTrajectory, queue_size=1,
                                    latch=True)
        trajectory = JointTrajectory()
        trajectory.joint_names = ['shoulder', 'elbow']
        for seconds, positions in ((0.5, [0.3, -0.2]), (1.0, [0.6, -0.4])):
            point = JointTrajectoryPoint()
            point.positions = positions
            point.time_from_start = rospy.Duration(seconds)
            trajectory.points.append(point)
        publisher.publish(trajectory)
        rospy.sleep(0.5)
        self.step(360)  # 1.5 s: the end, held for 0.5 s
        states = self.joint_states('arm3')
        self.assertAlmostEqual(0.6, states.position[0], delta=2e-4)
        self.assertAlmostEqual(-0.4, states.position[1], delta=2e-4)

    def test_command_takes_only_its_joints_from_a_trajectory(self):
        # ros_control's habit: an arm's trajectory and a gripper's command
        # are two controllers on disjoint joints. The elbow's command takes
        # the elbow alone; the shoulder follows its trajectory to the end.
        self.spawn_urdf('arm5', 'two_link_arm.urdf', 1.5)
        publisher = rospy.Publisher(SIM + 'arm5/joint_trajectory', JointTrajectory, queue_size=1,
                                    latch=True)
        trajectory = JointTrajectory()
        trajectory.joint_names = ['shoulder', 'elbow']
        point = JointTrajectoryPoint()
        point.positions = [0.6, -0.4]
        point.time_from_start = rospy.Duration(1.0)
        trajectory.points.append(point)
        publisher.publish(trajectory)
        rospy.sleep(0.5)
        self.step(60)  # 0.25 s into the trajectory
        self.command('arm5', name=['elbow'], position=[0.3])
        self.step(300)  # 1.5 s in all: the trajectory's end, held for 0.5 s
        states = self.joint_states('arm5')
        self.assertAlmostEqual(0.6, states.position[0], delta=2e-4)
        self.assertAlmostEqual(0.3, states.position[1], delta=2e-4)
        # A trajectory for the shoulder alone leaves the elbow's command.
        trajectory.joint_names = ['shoulder']
        point.positions = [-0.2]
        publisher.publish(trajectory)
        rospy.sleep(0.5)
        self.step(360)
        states = self.joint_states('arm5')
        self.assertAlmostEqual(-0.2, states.position[0], delta=2e-4)
        self.assertAlmostEqual(0.3, states.position[1], delta=2e-4)

    def test_world_joint_origin_places_the_model(self):
        # Gazebo and robot_state_publisher: the spawn pose is the URDF's
        # 'world' frame, and the root sits at the fixed joint's <origin>
        # from it. Spawn pose (1, 2, 0.3) turned 0.2 rad about z, origin
        # (0.5, 0, 1.2) turned 0.5 rad: the root at (1, 2, 0.3) + Rz(0.2)
        # (0.5, 0, 1.2), turned 0.7 rad; for a rigid model and an arm alike.
        link = ("<link name='base'><inertial><mass value='1'/><inertia ixx='0.01' iyy='0.01' "
                "izz='0.01' ixy='0' ixz='0' iyz='0'/></inertial><collision><geometry>"
                "<box size='0.1 0.1 0.1'/></geometry></collision></link>")
        arm = ("<joint name='hinge' type='revolute'><parent link='base'/><child link='rod'/>"
               "<axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='10' velocity='1'/>"
               "</joint><link name='rod'><inertial><origin xyz='0 0 -0.2'/><mass value='1'/>"
               "<inertia ixx='0.01' iyy='0.01' izz='0.01' ixy='0' ixz='0' iyz='0'/>"
               "</inertial></link>")
        yaw = 0.2
        for name, extra in (('mounted', ''), ('mounted_arm', arm)):
            request = SpawnRequest()
            request.name = name
            request.urdf = ("<robot name='r'><link name='world'/><joint name='fix' type='fixed'>"
                            "<parent link='world'/><child link='base'/>"
                            "<origin xyz='0.5 0 1.2' rpy='0 0 0.5'/></joint>" + link + extra +
                            "</robot>")
            request.pose.position.x, request.pose.position.y = 1.0, 2.0
            request.pose.position.z = 0.3
            request.pose.orientation.z, request.pose.orientation.w = (math.sin(yaw / 2),
                                                                      math.cos(yaw / 2))
            request.friction = -1.0
            request.restitution = -1.0
            response = self.spawn(request)
            self.assertTrue(response.success, response.message)
            self.addCleanup(self.delete, name)
            pose = self.get_state(name + '/base').pose
            self.assertAlmostEqual(1.0 + 0.5 * math.cos(yaw), pose.position.x, delta=1e-9)
            self.assertAlmostEqual(2.0 + 0.5 * math.sin(yaw), pose.position.y, delta=1e-9)
            self.assertAlmostEqual(0.3 + 1.2, pose.position.z, delta=1e-9)
            self.assertAlmostEqual(math.sin(0.35), pose.orientation.z, delta=1e-9)
            self.assertAlmostEqual(math.cos(0.35), pose.orientation.w, delta=1e-9)

    def test_tf_holds_the_link_frames(self):
        self.spawn_urdf('arm4', 'two_link_arm.urdf', 1.5, {'shoulder': math.pi / 2})
        self.step(1)
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        self.assertIsNotNone(listener)
        transform = buffer.lookup_transform('world', 'arm4/tool', rospy.Time(0),
                                            rospy.Duration(10.0))
        # The URDF tree: the world to the root link, each movable joint's
        # parent link to its child, the fixed tool mount static.
        frames = yaml.safe_load(buffer.all_frames_as_yaml())
        self.assertEqual('world', frames['arm4/base']['parent'])
        self.assertEqual('arm4/base', frames['arm4/upper_arm']['parent'])
        self.assertEqual('arm4/upper_arm', frames['arm4/forearm']['parent'])
        self.assertEqual('arm4/forearm', frames['arm4/tool']['parent'])
        tool = self.get_state('arm4/tool').pose.position
        self.assertAlmostEqual(tool.x, transform.transform.translation.x, delta=1e-3)
        self.assertAlmostEqual(tool.z, transform.transform.translation.z, delta=1e-3)

    def test_seven_dof_arm_holds_its_pose_and_falls_limp(self):
        pose = [0.3, -0.5, 0.2, -1.8, 0.1, 1.4, 0.5]
        joints = ['joint%d' % (i + 1) for i in range(7)]
        self.spawn_urdf('arm7', 'seven_dof_arm.urdf', 0.0, dict(zip(joints, pose)))
        self.command('arm7', name=joints, position=pose)
        self.step(5 * 240)
        states = self.joint_states('arm7')
        self.assertEqual(joints, list(states.name))
        for expected, actual in zip(pose, states.position):
            self.assertAlmostEqual(expected, actual, delta=1e-3)

        # Limp: every joint back to no command; the arm falls onto its limits
        # and the ground and comes to rest there, nothing through the ground.
        self.command('arm7', name=joints, effort=[0.0] * 7)
        self.step(5 * 240)
        states = self.joint_states('arm7')
        limits = [(-2.9, 2.9), (-1.76, 1.76), (-2.9, 2.9), (-3.07, -0.07), (-2.9, 2.9),
                  (-0.02, 3.75), (-2.9, 2.9)]
        for (lower, upper), position, velocity in zip(limits, states.position, states.velocity):
            self.assertTrue(math.isfinite(position) and math.isfinite(velocity))
            self.assertGreater(position, lower - 1e-3)
            self.assertLess(position, upper + 1e-3)
            self.assertLess(abs(velocity), 0.05)
        for link in range(8):
            origin = self.get_state('arm7/link%d' % link).pose.position
            self.assertGreater(origin.z, -0.01, 'link%d' % link)


if __name__ == '__main__':
    import rostest
    rospy.init_node('joints_test')
    rostest.rosrun(PKG, 'joints', JointsTest)
