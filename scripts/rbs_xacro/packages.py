"""Finding a ROS package's directory for $(find NAME): rospkg when it is
installed, else a walk of ROS_PACKAGE_PATH for the package.xml naming it."""

import os
import re

from .errors import _EvalError


def _package_name(package_xml):
    try:
        with open(package_xml, 'rb') as stream:
            data = stream.read(1024 * 1024)
        match = re.search(rb'<name>\s*([^<\s]+)\s*</name>', data)
        return match.group(1).decode('utf-8', 'replace') if match else None
    except OSError:
        return None


def find_package(name, roots=None, max_dirs=200000):
    """The directory of the package `name`: the first directory under `roots`
    (default: ROS_PACKAGE_PATH) whose package.xml names it. A package's own
    subdirectories are not searched, nor hidden ones or those with a
    CATKIN_IGNORE file."""
    if roots is None:
        roots = [p for p in os.environ.get('ROS_PACKAGE_PATH', '').split(os.pathsep) if p]
    visited = 0
    seen = set()
    for root in roots:
        for directory, subdirectories, files in os.walk(root, followlinks=True):
            real = os.path.realpath(directory)
            visited += 1
            if real in seen or visited > max_dirs:
                subdirectories[:] = []
                continue
            seen.add(real)
            if 'package.xml' in files:
                subdirectories[:] = []
                if _package_name(os.path.join(directory, 'package.xml')) == name:
                    return directory
                continue
            if 'CATKIN_IGNORE' in files:
                subdirectories[:] = []
                continue
            subdirectories[:] = sorted(d for d in subdirectories if not d.startswith('.'))
    return None


class _Packages:
    """$(find NAME) of one expansion: each name looked up once, with rospkg
    when this python3 has it, else with find_package."""

    def __init__(self):
        self.paths = {}
        self.rospack = None

    def find(self, package):
        if not package:
            raise _EvalError('$(find) needs a package name')
        if package in self.paths:
            return self.paths[package]
        path = None
        try:
            import rospkg
            if self.rospack is None:
                self.rospack = rospkg.RosPack()
            path = self.rospack.get_path(package)
        except ImportError:
            pass
        except Exception:  # rospkg.ResourceNotFound and its kin
            path = None
        if path is None:
            path = find_package(package)
        if path is None:
            raise _EvalError("package '%s' not found (ROS_PACKAGE_PATH=%s)"
                             % (package, os.environ.get('ROS_PACKAGE_PATH', '')))
        self.paths[package] = path
        return path
