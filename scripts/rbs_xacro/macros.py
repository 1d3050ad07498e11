"""Macros: their definition (parameters with defaults, ^ forwarding and
*block / **block), calls, and the insertion of blocks."""

import re

from . import limits
from .errors import XacroError, _EvalError
from .scopes import _Prop, _Scope
from .values import _Block, _literal, _MacroNamespace
from .xml_io import _Element, _Out, _OutComment

_DIRECTIVES = frozenset(['property', 'arg', 'macro', 'include', 'if', 'unless', 'insert_block',
                         'element', 'attribute', 'call'])


class _Macro:
    __slots__ = ('name', 'params', 'body', 'file', 'line', 'scope')

    def __init__(self, name, params, body, file, line, scope):
        self.name = name
        self.params = params
        self.body = body
        self.file = file
        self.line = line
        self.scope = scope


class _Param:
    __slots__ = ('name', 'block', 'default', 'forward')

    def __init__(self, name, block, default, forward):
        self.name = name
        self.block = block      # 0, 1 (*name) or 2 (**name)
        self.default = default  # text or None
        self.forward = forward  # ^: from the caller's scope


_PARAM_TOKEN = re.compile(r'''(?:\$\{[^}]*\}|'[^']*'|"[^"]*"|[^\s'"])+''')
_PARAM = re.compile(r'^(\*{0,2})([A-Za-z_]\w*)(?:(:=|=)(.*))?$', re.S)


class _Macros:
    """The macro part of the expander (mixed into _Expander, whose walk,
    value() and resolve() it uses)."""

    def _define_macro(self, node, scope):
        construct = '<%s>' % node.tag
        name = self._required(node, 'name').strip()
        if not name or name in _DIRECTIVES or any(c.isspace() for c in name):
            raise XacroError("'%s' cannot name a macro" % name, node.file, node.line, construct)
        params = []
        seen = set()
        for token in _PARAM_TOKEN.findall(node.get('params', '')):
            match = _PARAM.match(token)
            if not match:
                raise XacroError("macro '%s': parameter '%s' is not NAME, NAME:=DEFAULT, *NAME or "
                                 "**NAME" % (name, token), node.file, node.line, construct)
            stars, param, assign, default = match.groups()
            if param in seen:
                raise XacroError("macro '%s' has parameter '%s' twice" % (name, param), node.file,
                                 node.line, construct)
            seen.add(param)
            forward = False
            if assign is not None and default.startswith('^'):
                if default == '^':
                    forward, default = True, None
                elif default.startswith('^|'):
                    forward, default = True, default[2:]
            if stars and assign is not None:
                raise XacroError("macro '%s': block parameter '%s%s' cannot have a default"
                                 % (name, stars, param), node.file, node.line, construct)
            params.append(_Param(param, len(stars), default, forward))
        scope.macros[name] = _Macro(name, params, node.children, node.file, node.line, scope)

    def _find_macro(self, scope, name):
        head, *rest = name.split('.')
        macro = scope.find_macro(head)
        for part in rest:
            if not isinstance(macro, _MacroNamespace):
                return None
            macro = macro.scope.macros.get(part)
        return macro if isinstance(macro, _Macro) else None

    def _call(self, node, scope, out, name, skip=()):
        construct = '<%s>' % node.tag

        def fail(message):
            return XacroError(message, node.file, node.line, construct)

        macro = self._find_macro(scope, name)
        if macro is None:
            raise fail("unknown macro '%s' (not defined before this call%s)"
                       % (name, '' if name in _DIRECTIVES else
                          ', nor a xacro directive'))
        self.expansions += 1
        if self.expansions > limits.MAX_MACRO_EXPANSIONS:
            raise fail('more than %d macro expansions: the work is bounded'
                       % limits.MAX_MACRO_EXPANSIONS)
        self.macro_depth += 1
        self._enter(node)
        try:
            if self.macro_depth > limits.MAX_MACRO_DEPTH:
                raise fail("macro '%s' calls macros more than %d deep (recursion?)"
                           % (name, limits.MAX_MACRO_DEPTH))
            local = self._bind_arguments(node, scope, macro, name, skip, fail)
            try:
                self._nodes(macro.body, local, out)
            except XacroError as error:
                error.trace.append("in macro '%s' called at %s:%s" % (name, node.file, node.line))
                raise
        finally:
            self.macro_depth -= 1
            self.depth -= 1

    def _bind_arguments(self, node, scope, macro, name, skip, fail):
        """The scope of a call's macro body: the parameters from the call's
        attributes and child elements, the calling scope (^) and defaults."""
        local = _Scope(parent=scope, fallback=macro.scope)
        blocks = self._call_blocks(node, scope, macro, name, fail)
        given = self._given_arguments(node, scope, macro, name, skip, local, fail)
        for param in macro.params:
            if param.block:
                if not blocks:
                    raise fail("macro '%s' takes block parameter '%s%s', but the call has no "
                               "child element left for it"
                               % (name, '*' * param.block, param.name))
                element = blocks.pop(0)
                nodes = [element] if param.block == 1 else element.children
                local.props[param.name] = _Prop(param.name, _Block(nodes, True))
                continue
            if param.name in given:
                continue
            value = self._param_value(param, scope, local, macro, name, fail)
            local.props[param.name] = _Prop(param.name, value)
        if blocks:
            raise fail("macro '%s' was given %d child element(s) more than its block "
                       "parameters take" % (name, len(blocks)))
        return local

    def _call_blocks(self, node, scope, macro, name, fail):
        """The call's child elements, expanded, for the block parameters."""
        if any(param.block for param in macro.params):
            holder = _Out(None)
            self._nodes(node.children, scope, holder)
            return [child for child in holder.children if isinstance(child, _Out)]
        if any(isinstance(child, _Element) for child in node.children):
            raise fail("macro '%s' has no block parameters (*name, **name), but the call "
                       "has child elements" % name)
        return []

    def _given_arguments(self, node, scope, macro, name, skip, local, fail):
        """The names of the parameters the call's attributes give, set in `local`."""
        by_name = {param.name: param for param in macro.params}
        given = set()
        for attribute, raw in node.attrs:
            if attribute in skip or self._skip_attribute(node, attribute):
                continue
            param = by_name.get(attribute)
            if param is None or param.block:
                raise fail("macro '%s' has no parameter '%s'" % (name, attribute))
            value = _literal(self.value(raw, scope, node.file, node.line))
            local.props[attribute] = _Prop(attribute, value, file=node.file, line=node.line)
            given.add(attribute)
        return given

    def _param_value(self, param, scope, local, macro, name, fail):
        """A parameter the call does not give: from the calling scope (^), else
        its default (evaluated where the parameters before it are set)."""
        if param.forward:
            outer = scope.find_prop(param.name)
            if outer is not None:
                if outer.state == _Prop.DONE:
                    return outer.value
                return self.resolve(param.name, outer)
            if param.default is None:
                raise fail("macro '%s': parameter '%s' is to come from the calling scope "
                           "(^), which has no property '%s'" % (name, param.name, param.name))
        if param.default is None:
            raise fail("macro '%s' has no value for parameter '%s'" % (name, param.name))
        return _literal(self.value(param.default, local, macro.file, macro.line))

    def _insert_block(self, node, scope, out):
        name = self._string(self._required(node, 'name'), scope, node)
        prop = scope.find_prop(name)
        if prop is None:
            raise XacroError("undefined property '%s' (no block of that name)" % name, node.file,
                             node.line, '<%s>' % node.tag)
        if prop.state != _Prop.DONE or not isinstance(prop.value, _Block):
            raise XacroError("property '%s' is not a block" % name, node.file, node.line,
                             '<%s>' % node.tag)
        block = prop.value
        if block.expanded:
            for child in block.nodes:
                copy = self._copy(child, node)
                if isinstance(copy, str):
                    self._add_text(out, copy, node)
                else:
                    out.children.append(copy)
        else:
            self._enter(node)
            try:
                self._nodes(block.nodes, scope, out)
            finally:
                self.depth -= 1

    def _copy(self, item, node):
        if isinstance(item, _Out):
            copy = _Out(item.tag)
            self._count_element(node)
            copy.attrs = dict(item.attrs)
            try:
                self._charge_output(len(item.tag) + sum(len(k) + len(v) + 4
                                                        for k, v in item.attrs.items()))
            except _EvalError as error:
                raise XacroError(str(error), node.file, node.line, '<%s>' % node.tag) from None
            copy.children = [self._copy(child, node) for child in item.children]
            return copy
        if isinstance(item, _OutComment):
            return _OutComment(item.text)
        return item
