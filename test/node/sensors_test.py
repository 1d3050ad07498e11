#!/usr/bin/env python3
"""The URDF's Gazebo sensors through the node's topics, against closed
forms: a laser among walls and a post, an IMU, a bumper and ground-truth
odometry on a resting box, a force-torque sensor at a held arm's shoulder,
and a differential drive driven by cmd_vel."""
import math
import sys
import threading
import time
import unittest

import rospkg
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Pose, Twist, WrenchStamped
from nav_msgs.msg import Odometry
from rigid_body_sim.msg import Contacts
from rigid_body_sim.srv import Delete, GetState, Spawn, SpawnRequest, Step
from sensor_msgs.msg import Imu, JointState, LaserScan

PKG = 'rigid_body_sim'
SIM = '/rigid_body_sim/'
G = 9.81


def service(name, kind):
    rospy.wait_for_service(SIM + name, timeout=30.0)
    return rospy.ServiceProxy(SIM + name, kind, persistent=True)


class Latest:
    """Every message of a topic, kept in order."""

    def __init__(self, topic, kind):
        self.lock = threading.Lock()
        self.messages = []
        self.subscriber = rospy.Subscriber(topic, kind, self.on_message, queue_size=1000)

    def on_message(self, message):
        with self.lock:
            self.messages.append(message)

    def connect(self, timeout=10.0):
        """Waits until a publisher is connected, so no message is missed."""
        deadline = time.time() + timeout
        while time.time() < deadline and self.subscriber.get_num_connections() == 0:
            time.sleep(0.02)
        # rospy counts the connection before the publisher has added it.
        time.sleep(0.5)
        return self.subscriber.get_num_connections() > 0

    def wait(self, count, timeout=10.0):
        deadline = time.time() + timeout
        while time.time() < deadline:
            with self.lock:
                if len(self.messages) >= count:
                    return list(self.messages)
            time.sleep(0.02)
        with self.lock:
            return list(self.messages)


def box_urdf(name, size, static=True):
    inertial = ('<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    geometry = '<box size="%g %g %g"/>' % size
    return ('<robot name="%s"><link name="body">%s<collision><geometry>%s</geometry></collision>'
            '</link></robot>') % (name, inertial, geometry)


def cylinder_urdf(name, radius, length):
    inertial = ('<inertial><mass value="1"/><inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" '
                'iyz="0"/></inertial>')
    return ('<robot name="%s"><link name="body">%s<collision><geometry><cylinder radius="%g" '
            'length="%g"/></geometry></collision></link></robot>') % (name, inertial, radius,
                                                                     length)


class SensorsTest(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls.data = rospkg.RosPack().get_path(PKG) + '/test/data/sensors/'
        cls.spawn_service = service('spawn', Spawn)
        cls.delete = service('delete', Delete)
        cls.step = service('step', Step)
        cls.get_state = service('get_state', GetState)

    def spawn(self, name, urdf='', urdf_path='', xyz=(0, 0, 0), is_static=False, **kwargs):
        request = SpawnRequest(name=name, urdf=urdf, urdf_path=urdf_path, is_static=is_static,
                               friction=-1.0, restitution=-1.0, **kwargs)
        request.pose = Pose()
        request.pose.position.x, request.pose.position.y, request.pose.position.z = xyz
        request.pose.orientation.w = 1.0
        response = self.spawn_service(request)
        self.assertTrue(response.success, response.message)
        self.addCleanup(self.delete, name)
        return response

    def drive(self, name, namespace, odoms):
        """Drives the model at 0.1 m/s by cmd_vel for 5 s (1200 steps), and
        returns where it ends, the distance it travelled, its last odometry
        and the simulated time at the end (s)."""
        start = self.get_state(name).pose.position
        command = rospy.Publisher(namespace + '/cmd_vel', Twist, queue_size=1, latch=True)
        twist = Twist()
        twist.linear.x = 0.1
        command.publish(twist)
        time.sleep(1.0)
        first = len(odoms.wait(1))
        sim_time = self.step(1200).sim_time
        end = self.get_state(name).pose.position
        travelled = math.hypot(end.x - start.x, end.y - start.y)
        return end, travelled, odoms.wait(first + 150)[-1], sim_time

    def test_laser_ranges_in_a_known_room(self):
        # The post's laser is 0.5 m up at the origin; beams along +x, +y,
        # -x and -y. A wall's face at x = 1.9, a cylinder of radius 0.25 at
        # y = 1.5 (its face at 1.25), nothing along -x, a box's face at
        # y = -0.9.
        self.spawn('wall', urdf=box_urdf('wall', (0.2, 4, 2)), xyz=(2.0, 0, 1), is_static=True)
        self.spawn('pillar', urdf=cylinder_urdf('pillar', 0.25, 2), xyz=(0, 1.5, 1),
                   is_static=True)
        self.spawn('crate', urdf=box_urdf('crate', (1, 0.2, 2)), xyz=(0, -1.0, 1), is_static=True)
        scans = Latest(SIM + 'laser_post/scan', LaserScan)
        time.sleep(0.5)
        self.spawn('laser_post', urdf_path=self.data + 'laser_post.urdf')
        self.assertTrue(scans.connect())
        self.step(48)  # 0.2 s: two readings at 10 Hz
        messages = scans.wait(2)
        self.assertGreaterEqual(len(messages), 2)
        scan = messages[-1]
        self.assertEqual('laser_post/post', scan.header.frame_id)
        self.assertEqual(4, len(scan.ranges))
        self.assertAlmostEqual(0.0, scan.angle_min, places=6)
        self.assertAlmostEqual(math.pi / 2, scan.angle_increment, places=6)
        self.assertAlmostEqual(0.1, scan.range_min, places=6)
        self.assertAlmostEqual(5.0, scan.range_max, places=6)
        # float32 ranges: 1e-6 m is within their precision at these sizes.
        self.assertAlmostEqual(1.9, scan.ranges[0], delta=1e-6)
        self.assertAlmostEqual(1.25, scan.ranges[1], delta=1e-6)
        self.assertEqual(float('inf'), scan.ranges[2])
        self.assertAlmostEqual(0.9, scan.ranges[3], delta=1e-6)

    def test_imu_bumper_and_truth_on_a_resting_box(self):
        imus = Latest(SIM + 'imu_box/imu', Imu)
        bumps = Latest(SIM + 'imu_box/bumper', Contacts)
        truths = Latest(SIM + 'imu_box/truth', Odometry)
        time.sleep(0.5)
        self.spawn('imu_box', urdf_path=self.data + 'imu_box.urdf', xyz=(3, 3, 0.1))
        for topic in (imus, bumps, truths):
            self.assertTrue(topic.connect())
        self.step(240)
        imu = imus.wait(100)[-1]
        self.assertEqual('imu_box/base', imu.header.frame_id)
        self.assertAlmostEqual(G, imu.linear_acceleration.z, delta=1e-6)
        self.assertAlmostEqual(0.0, imu.linear_acceleration.x, delta=1e-6)
        self.assertAlmostEqual(0.0, imu.angular_velocity.z, delta=1e-6)
        self.assertAlmostEqual(1.0, imu.orientation.w, delta=1e-6)
        bump = bumps.wait(50)[-1]
        total = sum(contact.normal_force * contact.normal.z for contact in bump.contacts)
        self.assertTrue(all(contact.body_a == 'imu_box/base' for contact in bump.contacts))
        self.assertAlmostEqual(2.0 * G, total, delta=0.01 * 2.0 * G)
        truth = truths.wait(50)[-1]
        state = self.get_state('imu_box')
        self.assertEqual('world', truth.header.frame_id)
        self.assertEqual('imu_box/base', truth.child_frame_id)
        self.assertAlmostEqual(state.pose.position.z, truth.pose.pose.position.z, delta=1e-9)
        self.assertAlmostEqual(0.1, truth.pose.pose.position.z, delta=1e-3)

    def test_imu_on_a_turntable_reads_the_rate_and_the_centripetal_acceleration(self):
        imus = Latest(SIM + 'turntable/imu', Imu)
        self.spawn('turntable', urdf_path=self.data + 'turntable.urdf', xyz=(3, -3, 0))
        self.assertTrue(imus.connect())
        command = rospy.Publisher(SIM + 'turntable/joint_command', JointState, queue_size=1,
                                  latch=True)
        time.sleep(0.5)
        command.publish(JointState(name=['spin'], velocity=[2.0]))
        time.sleep(1.0)
        self.step(480)  # 2 s: up to speed within a step or two (100 N m on 0.75 kg m^2)
        imu = imus.wait(100)[-1]
        w, r = 2.0, 0.5
        self.assertAlmostEqual(w, imu.angular_velocity.z, delta=1e-4 * w)
        # Toward the axis: the sensor's -x.
        self.assertAlmostEqual(-w * w * r, imu.linear_acceleration.x, delta=1e-4 * w * w * r)
        self.assertAlmostEqual(0.0, imu.linear_acceleration.y, delta=1e-4 * w * w * r)
        self.assertAlmostEqual(G, imu.linear_acceleration.z, delta=1e-4 * G)

    def test_force_torque_at_a_held_shoulder(self):
        wrenches = Latest(SIM + 'ft_arm/shoulder_wrench', WrenchStamped)
        time.sleep(0.5)
        self.spawn('ft_arm', urdf_path=self.data + 'ft_arm.urdf', xyz=(-3, 3, 0), hold=True)
        self.assertTrue(wrenches.connect())
        self.step(240)
        wrench = wrenches.wait(50)[-1].wrench
        # The 2 kg upper arm's centre 0.25 m out, the 1 kg forearm's 0.7 m.
        weight = 3.0 * G
        moment = (2.0 * 0.25 + 1.0 * 0.7) * G
        self.assertAlmostEqual(weight, wrench.force.z, delta=1e-3 * weight)
        self.assertAlmostEqual(0.0, wrench.force.x, delta=1e-3 * weight)
        # The support's moment about y lifts the arm: -moment along y.
        self.assertAlmostEqual(-moment, wrench.torque.y, delta=1e-3 * moment)

    def test_diff_drive_moves_by_cmd_vel_and_its_odometry_agrees(self):
        odoms = Latest(SIM + 'diff_bot/odom', Odometry)
        scans = Latest(SIM + 'diff_bot/scan', LaserScan)
        time.sleep(0.5)
        self.spawn('diff_bot', urdf_path=self.data + 'diff_bot.urdf', xyz=(-3, -3, 0.05))
        self.assertTrue(odoms.connect() and scans.connect())
        self.step(120)  # settle on its wheels
        _, travelled, odom, _ = self.drive('diff_bot', SIM + 'diff_bot', odoms)
        self.assertAlmostEqual(0.5, travelled, delta=0.03 * 0.5)
        odom_travelled = math.hypot(odom.pose.pose.position.x, odom.pose.pose.position.y)
        self.assertAlmostEqual(travelled, odom_travelled, delta=0.02 * travelled)
        self.assertEqual('diff_bot/odom', odom.header.frame_id)
        self.assertEqual('diff_bot/base_link', odom.child_frame_id)
        scan = scans.wait(5)[-1]
        self.assertEqual(360, len(scan.ranges))
        stamps = [m.header.stamp.to_sec() for m in scans.wait(25)]
        periods = [b - a for a, b in zip(stamps, stamps[1:])]
        self.assertTrue(periods)
        for period in periods:
            self.assertAlmostEqual(0.2, period, delta=1e-6)

    def test_rover_xacro_drives_senses_and_publishes_one_tf_tree(self):
        """The drive demo's rover, from its xacro with a Gazebo include, as a
        TurtleBot3 user drives one: its topics under the spawn's robot
        namespace, as Gazebo puts them."""
        odoms = Latest('/rover_test/odom', Odometry)
        scans = Latest('/rover_test/scan', LaserScan)
        imus = Latest('/rover_test/imu', Imu)
        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)
        package = rospkg.RosPack().get_path(PKG)
        self.spawn('rover_test', urdf_path=package + '/urdf/rover/rover.urdf.xacro',
                   xyz=(3, -3, 0), robot_namespace='rover_test')
        self.assertTrue(odoms.connect() and scans.connect() and imus.connect())
        self.step(240)  # settle on its wheels and caster
        imu = imus.wait(200)[-1]
        self.assertAlmostEqual(G, imu.linear_acceleration.z, delta=1e-3)
        end, travelled, odom, sim_time = self.drive('rover_test', '/rover_test', odoms)
        self.assertAlmostEqual(0.5, travelled, delta=0.03 * 0.5)
        # The world source: odom is the world frame, so odom's pose is the
        # footprint's true pose.
        self.assertAlmostEqual(end.x, odom.pose.pose.position.x, delta=0.02 * travelled)
        self.assertAlmostEqual(end.y, odom.pose.pose.position.y, delta=0.02 * travelled)
        self.assertEqual('rover_test/odom', odom.header.frame_id)
        self.assertEqual('rover_test/base_footprint', odom.child_frame_id)
        scan = scans.wait(5)[-1]
        self.assertEqual(360, len(scan.ranges))
        self.assertEqual('rover_test/base_scan', scan.header.frame_id)
        # One tree: world -> rover_test/odom -> rover_test/base_footprint puts
        # the footprint where the node's own state says.
        # The transform of the drive's last step: the listener receives tf
        # after the step service answers, so the latest it holds may be an
        # earlier step's. Once it holds one within a microsecond of the end
        # (steps are 4 ms apart; the stamp's nanoseconds may round either
        # way), its latest is the last step's.
        deadline = time.time() + 10.0
        frame = 'rover_test/base_footprint'
        last_step = rospy.Time.from_sec(sim_time - 1e-6)
        while time.time() < deadline and not buffer.can_transform('world', frame, last_step):
            time.sleep(0.05)
        transform = buffer.lookup_transform('world', frame, rospy.Time(0)).transform
        self.assertAlmostEqual(end.x, transform.translation.x, delta=1e-3)
        self.assertAlmostEqual(end.y, transform.translation.y, delta=1e-3)
        self.assertEqual('world', buffer.lookup_transform(
            'world', 'rover_test/odom', rospy.Time(0)).header.frame_id)
        del listener


if __name__ == '__main__':
    rospy.init_node('sensors_test')
    rostest.rosrun(PKG, 'sensors', SensorsTest, sys.argv)
