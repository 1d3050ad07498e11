"""The values expressions see besides Python's own: blocks of XML, YAML
dicts with keys as attributes, include namespaces, helper namespaces; and the
conversions of property and parameter text (_literal, _to_bool)."""

import re

from .errors import _EvalError

_INT_LITERAL = re.compile(r'^\s*[-+]?\d+\s*$')
_FLOAT_LITERAL = re.compile(r'^\s*[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?\s*$')


class _Block:
    """XML given to a macro (*name, **name; already expanded) or a property block
    (expanded where it is inserted)."""
    __slots__ = ('nodes', 'expanded')

    def __init__(self, nodes, expanded):
        self.nodes = nodes
        self.expanded = expanded

    def __repr__(self):
        return '<xacro block>'


class YamlDict(dict):
    """A dict whose keys are also attributes: config.limits.lower."""

    def __repr__(self):
        return dict.__repr__(self)


class _Namespace:
    """The properties of an include with ns=: ${ns.name}."""

    def __init__(self, name, scope, expander):
        self._name = name
        self._scope = scope
        self._expander = expander

    def get(self, key):
        prop = self._scope.props.get(key)
        if prop is None:
            raise _EvalError("namespace '%s' has no property '%s'" % (self._name, key))
        return self._expander.resolve(key, prop)

    def __repr__(self):
        return '<xacro namespace %s>' % self._name


class _MacroNamespace:
    def __init__(self, scope):
        self.scope = scope


class _Helpers:
    """A namespace of callables and constants (math., xacro.)."""

    def __init__(self, name, members):
        self._name = name
        self._members = members

    def get(self, key):
        if key not in self._members:
            raise _EvalError("'%s' has no member '%s'" % (self._name, key))
        return self._members[key]

    def __repr__(self):
        return '<%s>' % self._name


def _literal(value):
    """A property's or a parameter's text as the number or boolean it spells,
    or without its single quotes; anything else as it is."""
    if not isinstance(value, str):
        return value
    if len(value) >= 2 and value[0] == "'" and value[-1] == "'":
        return value[1:-1]
    if '_' in value:
        return value
    if _INT_LITERAL.match(value):
        return int(value)
    if _FLOAT_LITERAL.match(value):
        return float(value)
    stripped = value.strip()
    if stripped in ('true', 'True'):
        return True
    if stripped in ('false', 'False'):
        return False
    return value


def _to_bool(value):
    if isinstance(value, str):
        text = value.strip()
        if text in ('true', 'True'):
            return True
        if text in ('false', 'False'):
            return False
        try:
            return bool(int(text))
        except ValueError:
            raise _EvalError('not a boolean (true, false, 1 or 0)') from None
    return bool(value)


def _dotify(value, memo=None):
    """YAML data with every dict a YamlDict (keys as attributes)."""
    if memo is None:
        memo = {}
    if id(value) in memo:
        return memo[id(value)]
    if isinstance(value, dict):
        result = YamlDict()
        memo[id(value)] = result
        for key, item in value.items():
            result[key] = _dotify(item, memo)
        return result
    if isinstance(value, list):
        result = []
        memo[id(value)] = result
        result.extend(_dotify(item, memo) for item in value)
        return result
    return value
