#!/usr/bin/env python3
"""A soak of the running node: spawn, delete, reset, wrench and step churn
for --seconds, then the node's resident memory against where it was after a
warm-up. Fails (exit 1) on a refused well-formed request, a dead node, or
RSS growth above --max-growth (fraction) after the warm-up.

Run by `make soak` (which starts the node); by hand:
  rosrun rigid_body_sim soak.py --seconds 3600
"""

import argparse
import os
import random
import subprocess
import sys
import time

import rospkg
import rospy
from geometry_msgs.msg import Point, Pose, Wrench
from rigid_body_sim.srv import (ApplyWrench, Delete, GetState, SetJointState, SetJointStateRequest,
                                Spawn, SpawnRequest, Step)
from std_srvs.srv import SetBool, Trigger

SIM = '/rigid_body_sim/'


def rss_kib(pid):
    with open('/proc/%d/status' % pid) as status:
        for line in status:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    raise RuntimeError('no VmRSS for pid %d' % pid)


def node_pid():
    output = subprocess.check_output(['pgrep', '-f', 'rigid_body_sim_node'], text=True)
    return int(output.split()[0])


class Soak:

    def __init__(self, package):
        def proxy(name, kind):
            rospy.wait_for_service(SIM + name, timeout=60)
            return rospy.ServiceProxy(SIM + name, kind, persistent=False)
        self.spawn = proxy('spawn', Spawn)
        self.delete = proxy('delete', Delete)
        self.reset = proxy('reset_world', Trigger)
        self.wrench = proxy('apply_wrench', ApplyWrench)
        self.step = proxy('step', Step)
        self.paused = proxy('set_paused', SetBool)
        self.get_state = proxy('get_state', GetState)
        self.set_joint_state = proxy('set_joint_state', SetJointState)
        self.urdfs = [package + '/urdf/' + name for name in
                      ('box.urdf', 'sphere.urdf', 'cylinder.urdf', 'mesh_object.urdf',
                       'compound.urdf', 'demo_cube.urdf')]
        self.arm = package + '/test/data/two_link_arm.urdf'
        self.live = []
        self.counter = 0
        self.calls = 0

    def check(self, response, what):
        self.calls += 1
        if not response.success:
            raise RuntimeError('%s refused: %s' % (what, response.message))

    def spawn_one(self):
        self.counter += 1
        name = 'soak_%d' % self.counter
        request = SpawnRequest(name=name, friction=-1.0, restitution=-1.0)
        arm = self.counter % 7 == 0
        request.urdf_path = self.arm if arm else random.choice(self.urdfs)
        request.pose = Pose()
        request.pose.position.x = random.uniform(-20, 20)
        request.pose.position.y = random.uniform(-20, 20)
        request.pose.position.z = random.uniform(1.0, 3.0)
        request.pose.orientation.w = 1.0
        self.check(self.spawn(request), 'spawn ' + name)
        self.live.append((name, arm))

    def round(self):
        while len(self.live) < 40:
            self.spawn_one()
        for _ in range(5):
            name, arm = self.live.pop(random.randrange(len(self.live)))
            self.check(self.delete(name), 'delete ' + name)
        name, arm = random.choice(self.live)
        wrench = Wrench()
        wrench.force.x = random.uniform(-50, 50)
        self.check(self.wrench(name=name, point=Point(), wrench=wrench, duration=0.1),
                   'wrench ' + name)
        if arm:
            request = SetJointStateRequest(model=name, joint_names=['elbow'],
                                           positions=[random.uniform(-2, 2)])
            self.check(self.set_joint_state(request), 'set_joint_state ' + name)
        self.check(self.step(steps=24), 'step')
        self.check(self.get_state(name=name), 'get_state ' + name)
        if self.counter % 50 == 0:
            self.check(self.reset(), 'reset_world')


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--seconds', type=float, default=3600.0)
    parser.add_argument('--warmup', type=float, default=60.0)
    parser.add_argument('--max-growth', type=float, default=0.05)
    parser.add_argument('--report', type=float, default=300.0, help='seconds between RSS lines')
    args = parser.parse_args(rospy.myargv()[1:])
    rospy.init_node('soak', anonymous=True)
    random.seed(1)
    soak = Soak(rospkg.RosPack().get_path('rigid_body_sim'))
    soak.check(soak.paused(True), 'set_paused')
    pid = node_pid()
    start = time.time()
    baseline = None
    peak = 0
    next_report = start + args.report
    while time.time() - start < args.seconds:
        soak.round()
        if baseline is None and time.time() - start >= args.warmup:
            baseline = rss_kib(pid)
        peak = max(peak, rss_kib(pid))
        if time.time() >= next_report:
            next_report += args.report
            print('soak: %.0f s, %d spawns, RSS %d KiB' % (time.time() - start, soak.counter,
                                                          rss_kib(pid)), flush=True)
    end = rss_kib(pid)
    baseline = baseline or end
    growth = (end - baseline) / baseline
    print('soak: %.0f s, %d spawns, %d calls, RSS %d KiB after warm-up, %d KiB at the end '
          '(%+.1f %%), peak %d KiB' % (time.time() - start, soak.counter, soak.calls, baseline,
                                        end, 100 * growth, peak))
    if growth > args.max_growth:
        print('soak: RSS grew beyond %.0f %%' % (100 * args.max_growth))
        return 1
    return 0


if __name__ == '__main__':
    sys.exit(main())
