#!/usr/bin/env python3
"""Node memory over many refused mesh spawns (issue 21: RSS stays flat).

Spawns a model whose mesh assimp reads but whose hull is refused (a DAE
with one triangle) COUNT times through ~spawn and prints the node's RSS
before and after, and the cost of a cached mesh spawn. Needs a running
node: `rosrun rigid_body_sim rigid_body_sim_node`.
"""
import argparse
import os
import tempfile
import time
import xmlrpc.client

import rosgraph
import rospy
from rigid_body_sim.srv import Delete, Spawn, SpawnRequest

NODE = '/rigid_body_sim'
FLAT_DAE = """<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="a" count="9">0 0 0 1 0 0 0 1 0</float_array>
<technique_common><accessor source="#a" count="3" stride="3"><param name="X" type="float"/>
<param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node><instance_geometry url="#g"/></node>
</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
"""


def node_rss_kb():
    uri = rosgraph.Master('/mesh_rss').lookupNode(NODE)
    pid = xmlrpc.client.ServerProxy(uri).getPid('/mesh_rss')[2]
    with open('/proc/%d/status' % pid) as status:
        for line in status:
            if line.startswith('VmRSS:'):
                return int(line.split()[1])
    return -1


def urdf(mesh):
    return ("<robot name='m'><link name='base_link'><collision><geometry>"
            "<mesh filename='%s'/></geometry></collision></link></robot>" % mesh)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument('--count', type=int, default=3000)
    args = parser.parse_args()
    rospy.init_node('mesh_rss', anonymous=True)
    rospy.wait_for_service(NODE + '/spawn', timeout=30)
    spawn = rospy.ServiceProxy(NODE + '/spawn', Spawn, persistent=True)
    delete = rospy.ServiceProxy(NODE + '/delete', Delete)
    with tempfile.TemporaryDirectory() as directory:
        flat = os.path.join(directory, 'flat.dae')
        with open(flat, 'w') as out:
            out.write(FLAT_DAE)
        request = SpawnRequest(name='refused', urdf=urdf(flat), friction=-1, restitution=-1)
        request.pose.orientation.w = 1.0
        before = node_rss_kb()
        start = time.monotonic()
        refused = 0
        for _ in range(args.count):
            refused += 0 if spawn(request).success else 1
        seconds = time.monotonic() - start
        after = node_rss_kb()
        print('[measured] %d hostile mesh spawns (%d refused) in %.1f s: node RSS %.1f -> %.1f MB '
              '(%+.1f MB)' % (args.count, refused, seconds, before / 1024, after / 1024,
                              (after - before) / 1024))
    box = os.path.join(os.path.dirname(os.path.abspath(__file__)), '..', 'test', 'data',
                       'chamfered_box.obj')
    request = SpawnRequest(urdf=urdf(os.path.abspath(box)), friction=-1, restitution=-1)
    request.pose.orientation.w = 1.0
    request.pose.position.z = 100.0
    times = []
    for i in range(21):
        request.name = 'cached%d' % i
        start = time.monotonic()
        assert spawn(request).success
        times.append(time.monotonic() - start)
        delete(request.name)
    times = sorted(times[1:])  # the first one starts the helper
    print('[measured] cached mesh spawn: median %.2f ms, max %.2f ms (service round trip)' %
          (1e3 * times[len(times) // 2], 1e3 * times[-1]))


if __name__ == '__main__':
    main()
