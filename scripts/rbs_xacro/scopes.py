"""Properties and the scopes that hold them and macros."""


class _Prop:
    __slots__ = ('name', 'value', 'raw', 'state', 'scope', 'file', 'line')
    RAW, BUSY, DONE = 0, 1, 2

    def __init__(self, name, value=None, raw=None, scope=None, file=None, line=None):
        self.name = name
        self.value = value
        self.raw = raw
        self.state = _Prop.DONE if raw is None else _Prop.RAW
        self.scope = scope
        self.file = file
        self.line = line


class _Scope:
    """Properties and macros. A macro's body sees its parameters, then its
    caller's names (xacro scopes dynamically), then those where the macro
    was defined (the fallback: an include's own properties)."""

    def __init__(self, parent=None, fallback=None):
        self.parent = parent
        self.fallback = fallback
        self.props = {}
        self.macros = {}

    def _chains(self):
        seen = set()
        pending = [self]
        while pending:
            scope = pending.pop(0)
            while scope is not None and id(scope) not in seen:
                seen.add(id(scope))
                yield scope
                if scope.fallback is not None:
                    pending.append(scope.fallback)
                scope = scope.parent

    def find_prop(self, name):
        for scope in self._chains():
            prop = scope.props.get(name)
            if prop is not None:
                return prop
        return None

    def find_macro(self, name):
        for scope in self._chains():
            macro = scope.macros.get(name)
            if macro is not None:
                return macro
        return None
