"""rigid_body_sim's xacro: expands ROS .xacro robot descriptions to URDF.

Debian ships no xacro, so this is our own, written from the documented
xacro language (the ROS wiki page and the xacro README), standard library
only (PyYAML for xacro.load_yaml, rospkg for $(find) when they are there).
scripts/xacro is its command line; spawn_model and the tests import it.

Supported: xacro:property (value, lazy_eval, default, remove, scope="parent"
and "global", property blocks), xacro:arg and $(arg), xacro:macro with
default (x:=1), forwarded (x:=^, x:=^|default) and block (*b, **b)
parameters, xacro:insert_block, macro calls (<xacro:NAME>, xacro:call),
xacro:include (relative, $(find), glob patterns, ns=), xacro:if and
xacro:unless, xacro:element and xacro:attribute, ${...} Python expressions
(evaluated by a restricted interpreter of our own: no imports, no names
starting with '__' nor attributes starting with '_', bounded work),
$(find), $(env), $(optenv), $(eval), $(dirname), $(anon), $${ and $$(
escapes, xacro.load_yaml with !degrees and !radians. Values are converted
with str(), as xacro does.

A file is xacro when its name ends in .xacro or its root element declares
the xacro namespace; any other file is passed through as it is.

The API:
  expand_file(path, args) -> str       the URDF of a file
  expand_string(text, args, base_dir=None) -> str
  is_xacro(text, path=None) -> bool
  find_package(name, roots=None) -> str or None
  parse_mappings(['name:=value', ...]) -> {name: value}
  XacroError                           the one exception of a bad description
  main(argv=None) -> exit status       the command line (cli.py)
  MAX_...                              the bounds (limits.py); setting one
                                       here sets it for the next expansion

The modules, in the order of their dependencies:
  limits, errors     the bounds; XacroError and an expression's _EvalError
  xml_io             parsing with line numbers, the output tree, serialisation
  values             blocks, YAML dicts, namespaces; literals and booleans
  bounds             the work budget of expressions
  whitelist          the builtins, math and methods expressions may use
  expressions        the restricted expression interpreter
  packages           $(find): rospkg, or a walk of ROS_PACKAGE_PATH
  scopes             properties and scopes
  substitution       ${...} and $(...) in attribute values and text
  xacro_helpers      the xacro.* functions (load_yaml, ...)
  macros             macro definitions, calls and blocks
  expander           the walk: properties, args, conditionals, includes
  api, cli           the functions above; the command line and --rbs-reply
"""

import sys
import types

from . import limits
from .api import expand_file, expand_string, parse_mappings
from .cli import main
from .errors import XacroError
from .packages import find_package
from .xml_io import is_xacro

__all__ = ['expand_file', 'expand_string', 'is_xacro', 'find_package', 'parse_mappings',
           'XacroError', 'main']


class _Package(types.ModuleType):
    """This package's module: its MAX_... names are those of limits.py, read
    and set there, so that `rbs_xacro.MAX_ELEMENTS = 50` bounds the expansions
    that follow, as it did when the expander was one file."""

    def __getattr__(self, name):
        if name in limits.NAMES:
            return getattr(limits, name)
        raise AttributeError("module '%s' has no attribute '%s'" % (self.__name__, name))

    def __setattr__(self, name, value):
        if name in limits.NAMES:
            setattr(limits, name, value)
        else:
            super().__setattr__(name, value)

    def __dir__(self):
        return sorted(set(super().__dir__()) | limits.NAMES)


sys.modules[__name__].__class__ = _Package
