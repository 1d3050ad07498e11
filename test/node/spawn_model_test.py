#!/usr/bin/env python3
"""gazebo_ros's spawning idioms against rigid_body_sim, verbatim with this
package's name, plus the world services they lean on.

Run by spawn_model_test.test: the node starts paused with the arm of
test/data/arm.urdf as robot_description. Every test uses models of its own.
"""

import math
import os
import shutil
import subprocess
import tempfile
import time
import unittest

import rospkg
import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rigid_body_sim.srv import (GetModelProperties, GetPhysics, GetState, GetWorldProperties,
                                SetPhysics, SetPhysicsRequest, SetState, SetStateRequest,
                                Step)
from std_srvs.srv import SetBool, Trigger

PKG = 'rigid_body_sim'
SIM = '/rigid_body_sim/'
TIMEOUT = 60.0  # s of wall time for one spawn_model run


def spawn_model(*args, cwd=None, env=None):
    """Runs `rosrun rigid_body_sim spawn_model ARGS`; (exit status, output)."""
    process = subprocess.run(['rosrun', PKG, 'spawn_model'] + list(args), cwd=cwd, env=env,
                             stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                             universal_newlines=True, timeout=TIMEOUT)
    return process.returncode, process.stdout


def service(name, service_type):
    rospy.wait_for_service(SIM + name, timeout=30)
    return rospy.ServiceProxy(SIM + name, service_type)


class SpawnModelTest(unittest.TestCase):

    def setUp(self):
        self.package = rospkg.RosPack().get_path(PKG)
        self.get_state = service('get_state', GetState)
        self.world = service('get_world_properties', GetWorldProperties)
        self.model = service('get_model_properties', GetModelProperties)
        self.set_paused = service('set_paused', SetBool)
        self.set_paused(True)

    def assertAtSpawnPose(self, name):
        pose = self.get_state(name).pose.position
        for expected, actual in zip((10.0, 0.0, 20.0), (pose.x, pose.y, pose.z)):
            self.assertAlmostEqual(expected, actual, delta=1e-12)

    def assertSpawned(self, result):
        status, output = result
        self.assertEqual(0, status, output)

    def test_urdf_param_spawns_the_robot_description_with_its_masses(self):
        self.assertSpawned(spawn_model('-urdf', '-param', 'robot_description', '-model',
                                       'arm_param', '-z', '2'))
        self.assertIn('arm_param', self.world().model_names)
        props = self.model('arm_param')
        self.assertTrue(props.success, props.message)
        self.assertEqual('base', props.root_link)
        self.assertEqual(['base', 'forearm', 'tool'], list(props.link_names))
        self.assertEqual([1.5, 0.75, 0.125], list(props.link_masses))
        self.assertEqual(2.375, props.mass)
        self.assertEqual(['elbow', 'tool_mount'], list(props.joint_names))
        self.assertEqual(['revolute', 'fixed'], list(props.joint_types))
        self.assertEqual([0.0, 0.0], list(props.joint_positions))
        self.assertFalse(props.is_static)

    def test_urdf_file_relative_to_the_callers_directory_and_home(self):
        caller = tempfile.mkdtemp()
        try:
            os.mkdir(os.path.join(caller, 'models'))
            # The URDF names its mesh relative to itself; both are found from
            # the caller's directory, which the node never sees.
            for name in ('relative_mesh.urdf', 'chamfered_box.ply'):
                shutil.copy(os.path.join(self.package, 'test', 'data', name),
                            os.path.join(caller, 'models', name))
            self.assertSpawned(spawn_model('-urdf', '-file', 'models/relative_mesh.urdf',
                                           '-model', 'relative_file', '-z', '3', cwd=caller))
            env = dict(os.environ, HOME=caller)
            self.assertSpawned(spawn_model('-urdf', '-file', '~/models/relative_mesh.urdf',
                                           '-model', 'home_file', '-x', '2', '-z', '3',
                                           cwd='/', env=env))
        finally:
            shutil.rmtree(caller)
        # Mass from the chamfered box's geometry at the default 1000 kg/m^3:
        # the 0.5 x 0.25 x 0.125 m box less a corner tetrahedron of legs
        # 0.125, 0.0625, 0.03125 m.
        volume = 0.5 * 0.25 * 0.125 - 0.125 * 0.0625 * 0.03125 / 6.0
        for name in ('relative_file', 'home_file'):
            props = self.model(name)
            self.assertTrue(props.success, props.message)
            self.assertAlmostEqual(1000.0 * volume, props.link_masses[0], delta=1e-9)

    def test_J_sets_the_initial_joint_position(self):
        self.assertSpawned(spawn_model('-urdf', '-param', 'robot_description', '-model',
                                       'arm_bent', '-x', '-2', '-z', '2', '-J', 'elbow', '0.5'))
        self.assertEqual([0.5, 0.0], list(self.model('arm_bent').joint_positions))
        forearm = self.get_state('arm_bent/forearm')
        self.assertTrue(forearm.success, forearm.message)
        q = forearm.pose.orientation
        self.assertAlmostEqual(math.sin(0.25), q.z, delta=1e-12)
        self.assertAlmostEqual(math.cos(0.25), q.w, delta=1e-12)
        # The tool sits 0.5 m along the turned forearm from the elbow at x = -1.75.
        tool = self.get_state('arm_bent/tool').pose.position
        self.assertAlmostEqual(-1.75 + 0.5 * math.cos(0.5), tool.x, delta=1e-12)
        self.assertAlmostEqual(0.5 * math.sin(0.5), tool.y, delta=1e-12)
        self.assertAlmostEqual(2.0, tool.z, delta=1e-12)

    def test_J_outside_the_limits_or_of_no_joint_is_refused(self):
        status, output = spawn_model('-urdf', '-param', 'robot_description', '-model',
                                     'arm_over', '-J', 'elbow', '2')
        self.assertEqual(1, status)
        self.assertIn("joint 'elbow' position 2 rad is outside its limits [-1.5, 1.5]", output)
        status, output = spawn_model('-urdf', '-param', 'robot_description', '-model',
                                     'arm_fixed', '-J', 'tool_mount', '0.1')
        self.assertEqual(1, status)
        self.assertIn("joint 'tool_mount' is not a movable joint of the model; movable: 'elbow'",
                      output)
        names = self.world().model_names
        self.assertNotIn('arm_over', names)
        self.assertNotIn('arm_fixed', names)

    def test_unpause_runs_the_simulation(self):
        self.assertTrue(self.world().paused)
        self.assertSpawned(spawn_model('-urdf', '-file', os.path.join(self.package, 'urdf',
                                                                     'box.urdf'),
                                       '-model', 'unpaused_box', '-x', '4', '-z', '5',
                                       '-unpause'))
        self.assertFalse(self.world().paused)
        start = self.world().sim_time
        deadline = time.monotonic() + 10.0
        while self.world().sim_time <= start and time.monotonic() < deadline:
            time.sleep(0.05)
        self.assertGreater(self.world().sim_time, start)

    def test_wait_holds_the_spawn_until_the_model_exists(self):
        box = os.path.join(self.package, 'urdf', 'box.urdf')
        waiting = subprocess.Popen(
            ['rosrun', PKG, 'spawn_model', '-urdf', '-file', box, '-model', 'waiting_box',
             '-x', '6', '-z', '5', '-wait', 'awaited_box'],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        try:
            time.sleep(3.0)
            self.assertIsNone(waiting.poll(), 'spawn_model -wait returned before the model came')
            self.assertNotIn('waiting_box', self.world().model_names)
            self.assertSpawned(spawn_model('-urdf', '-file', box, '-model', 'awaited_box',
                                           '-x', '8', '-z', '5'))
            output, _ = waiting.communicate(timeout=TIMEOUT)
        finally:
            if waiting.poll() is None:
                waiting.kill()
        self.assertEqual(0, waiting.returncode, output)
        self.assertIn('waiting_box', self.world().model_names)

    def test_reference_frame_places_the_model_in_that_frame(self):
        box = os.path.join(self.package, 'urdf', 'box.urdf')
        # A static table turned a quarter turn about z at (1, 2, 0.5).
        self.assertSpawned(spawn_model('-urdf', '-file', box, '-model', 'ref_table', '-static',
                                       '-x', '1', '-y', '2', '-z', '0.5', '-Y',
                                       repr(math.pi / 2)))
        self.assertSpawned(spawn_model('-urdf', '-file', box, '-model', 'ref_cup',
                                       '-reference_frame', 'ref_table/base_link',
                                       '-x', '1', '-z', '1.5'))
        cup = self.get_state('ref_cup').pose
        # The table's x axis is the world's y.
        self.assertAlmostEqual(1.0, cup.position.x, delta=1e-12)
        self.assertAlmostEqual(3.0, cup.position.y, delta=1e-12)
        self.assertAlmostEqual(2.0, cup.position.z, delta=1e-12)
        self.assertAlmostEqual(math.sin(math.pi / 4), cup.orientation.z, delta=1e-12)
        self.assertAlmostEqual(math.cos(math.pi / 4), cup.orientation.w, delta=1e-12)
        props = self.model('ref_table')
        self.assertTrue(props.is_static)
        self.assertEqual(0.0, props.mass)
        status, output = spawn_model('-urdf', '-file', box, '-model', 'lost_cup',
                                     '-reference_frame', 'no_table/base_link')
        self.assertEqual(1, status)
        self.assertIn("no model named 'no_table'", output)

    def next_diagnostics(self):
        """The physics status of the next /diagnostics message after the call."""
        message = rospy.wait_for_message('/diagnostics', DiagnosticArray, timeout=10)
        statuses = [status for status in message.status
                    if status.name == 'rigid_body_sim: physics']
        self.assertEqual(1, len(statuses), message)
        return statuses[0], {value.key: value.value for value in statuses[0].values}

    def test_diagnostics_report_the_world_and_warn_when_real_time_is_lost(self):
        status, values = self.next_diagnostics()
        self.assertEqual(DiagnosticStatus.OK, status.level)
        self.assertEqual('paused', status.message)
        self.assertEqual(str(len(self.world().model_names)), values['models'])
        physics = service('get_physics', GetPhysics)()
        set_physics = service('set_physics', SetPhysics)
        # A million times real time needs 2.4e8 steps/s: out of reach.
        self.assertTrue(set_physics(SetPhysicsRequest(keep_gravity=True, time_step=0.0,
                                                      real_time_factor=1e6)).success)
        try:
            self.set_paused(False)
            self.next_diagnostics()  # the window that saw the change
            status, values = self.next_diagnostics()
            self.assertEqual(DiagnosticStatus.WARN, status.level, status.message)
            self.assertIn('real-time factor 1e+06 cannot be held', status.message)
            self.assertLess(float(values['real-time factor achieved']), 0.9e6)
            self.assertGreater(int(values['steps in window']), 0)
            self.assertGreater(float(values['step time mean (ms)']), 0.0)
        finally:
            self.set_paused(True)
            set_physics(SetPhysicsRequest(keep_gravity=True, time_step=0.0,
                                          real_time_factor=physics.real_time_factor))

    def test_world_entries_place_movable_joints(self):
        props = self.model('arm_world')
        self.assertTrue(props.success, props.message)
        self.assertEqual([-0.75, 0.0], list(props.joint_positions))
        q = self.get_state('arm_world/forearm').pose.orientation
        self.assertAlmostEqual(math.sin(-0.375), q.z, delta=1e-12)
        self.assertAlmostEqual(math.cos(-0.375), q.w, delta=1e-12)

    def test_unknown_model_properties_are_refused(self):
        props = self.model('no_such_model')
        self.assertFalse(props.success)
        self.assertEqual("no model named 'no_such_model'", props.message)

    def test_reset_world_keeps_time_and_reset_simulation_restarts_it(self):
        box = os.path.join(self.package, 'urdf', 'box.urdf')
        self.assertSpawned(spawn_model('-urdf', '-file', box, '-model', 'reset_box', '-x', '10',
                                       '-z', '20'))
        self.set_paused(True)
        stepped = service('step', Step)(120)
        self.assertTrue(stepped.success, stepped.message)
        moved = SetStateRequest()
        moved.name = 'reset_box'
        moved.pose.position.x, moved.pose.position.z = 12.0, 30.0
        moved.pose.orientation.w = 1.0
        self.assertTrue(service('set_state', SetState)(moved).success)
        self.assertTrue(service('reset_world', Trigger)().success)
        self.assertEqual(stepped.sim_time, self.world().sim_time)
        self.assertAtSpawnPose('reset_box')
        self.assertTrue(service('reset_simulation', Trigger)().success)
        self.assertEqual(0.0, self.world().sim_time)
        self.assertAtSpawnPose('reset_box')


if __name__ == '__main__':
    import rostest
    rospy.init_node('spawn_model_test', anonymous=True)
    rostest.rosrun(PKG, 'spawn_model', SpawnModelTest)
