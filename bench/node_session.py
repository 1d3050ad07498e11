"""The node under a master of its own, for the benchmarks that time it through ROS.

  with NodeSession('spawn_bench') as rospy: ...

Starts roslaunch rigid_body_sim sim.launch on a free port (wall-clock time),
connects this process as a ROS node once the master answers, and stops the
launch (SIGINT, then SIGKILL after 15 s) when the block ends.
"""
import os
import signal
import socket
import subprocess
import time


def free_port():
    with socket.socket() as probe:
        probe.bind(('localhost', 0))
        return probe.getsockname()[1]


class NodeSession:
    def __init__(self, client_name):
        self.client_name = client_name
        self.launch = None

    def __enter__(self):
        port = free_port()
        os.environ['ROS_MASTER_URI'] = f'http://localhost:{port}'
        self.launch = subprocess.Popen(
            ['roslaunch', '-p', str(port), 'rigid_body_sim', 'sim.launch', 'use_sim_time:=false'],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, start_new_session=True)
        try:
            import rospy
            deadline = time.time() + 60.0
            while True:
                try:
                    rospy.init_node(self.client_name, anonymous=True, disable_signals=True)
                    return rospy
                except Exception:  # the master is not up yet
                    if time.time() > deadline:
                        raise
                    time.sleep(0.5)
        except BaseException:
            self.stop()
            raise

    def __exit__(self, *exc):
        self.stop()
        return False

    def stop(self):
        os.killpg(self.launch.pid, signal.SIGINT)
        try:
            self.launch.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(self.launch.pid, signal.SIGKILL)
            self.launch.wait()
