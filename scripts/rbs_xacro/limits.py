"""Bounds on one expansion: a hostile description ends in an error, never in
a hang or an exhausted machine.

The expander reads these as limits.NAME when it checks, so a caller (a test)
may lower one for a while: rbs_xacro.MAX_ELEMENTS = 50 sets it here.
"""

MAX_MACRO_DEPTH = 100              # macro calls inside macro calls
MAX_MACRO_EXPANSIONS = 10000       # macro calls in one expansion
MAX_OUTPUT_BYTES = 64 * 1024 * 1024
MAX_ELEMENTS = 250000              # elements in the output
MAX_FILE_BYTES = 64 * 1024 * 1024  # one input or YAML file
MAX_INCLUDES = 1000                # includes in one expansion
MAX_INCLUDE_DEPTH = 50             # includes inside includes
MAX_NESTING = 1000                 # elements inside elements, in one file
MAX_DEPTH = 2000                   # elements, calls and includes inside each other
MAX_PROPERTY_DEPTH = 500           # properties whose values name properties ...
MAX_EVAL_STEPS = 5000000           # expression nodes (and bytes / 64) evaluated
MAX_CONTAINER = 1000000            # elements of one list, tuple, dict or set
MAX_INT_BITS = 100000
MAX_FORMAT_WIDTH = 10000
MAX_LAMBDA_DEPTH = 200

NAMES = frozenset(name for name in list(globals()) if name.startswith('MAX_'))
