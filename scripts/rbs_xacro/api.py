"""The module API: expand a file or a string, parse name:=value words."""

import os

from . import limits
from .errors import XacroError
from .expander import _Expander
from .xml_io import _parse_xml, _read_limited, is_xacro


def expand_file(path, args=None, warn=None):
    """The URDF of the description at `path`, with `args` ({name: value}) as
    its $(arg ...) values; a file that is not xacro comes back as it is.
    Raises XacroError."""
    data = _read_limited(path)
    if not is_xacro(data, path):
        return data.decode('utf-8')
    expander = _Expander(args, os.path.dirname(os.path.abspath(path)), warn)
    root = _parse_xml(data, path)
    return expander.expand(root, path)


def expand_string(text, args=None, base_dir=None, warn=None):
    """As expand_file for a description given as text; relative includes and
    $(dirname) resolve against `base_dir` (default: the working directory)."""
    if not is_xacro(text):
        return text
    expander = _Expander(args, os.path.abspath(base_dir) if base_dir else None, warn)
    if len(text) > limits.MAX_FILE_BYTES:
        raise XacroError('the description is larger than %d bytes' % limits.MAX_FILE_BYTES,
                         '<string>')
    root = _parse_xml(text, '<string>')
    return expander.expand(root, None)


def parse_mappings(words):
    """{name: value} of name:=value words; ROS's own __name:= words are skipped."""
    args = {}
    for word in words:
        name, sep, value = word.partition(':=')
        if not sep or not name:
            raise ValueError("'%s' is not name:=value" % word)
        if not name.startswith('__'):
            args[name] = value
    return args
