"""The expander: the walk of the input tree that writes the output tree,
with properties, args, conditionals, xacro:element and xacro:attribute, and
includes; macros (macros.py), evaluation (substitution.py) and the xacro.*
functions (xacro_helpers.py) are mixed in."""

import glob
import keyword
import os
import sys

from . import limits
from .errors import XacroError, _EvalError
from .expressions import _Interpreter
from .macros import _Macros
from .packages import _Packages
from .scopes import _Prop, _Scope
from .substitution import _Substitutions, _is_real_file
from .values import _Block, _Helpers, _MacroNamespace, _Namespace, _dotify, _literal, _to_bool
from .whitelist import _make_builtins
from .xacro_helpers import _XacroHelpers, _tokenize
from .xml_io import (_BAD_XML_CHARS, _XML_NAME, _Comment, _Out, _OutComment, _Text, _parse_xml,
                     _read_limited, _serialize)

_DEFINITIONS = frozenset(['property', 'arg', 'macro', 'include'])


class _Expander(_Substitutions, _Macros, _XacroHelpers):
    """One expansion: its args, its global scope, its bounds' counters, the
    files it has parsed and the packages it has found."""

    def __init__(self, args=None, base_dir=None, warn=None):
        self.args = {str(k): str(v) for k, v in (args or {}).items()}
        self.arg_defaults = {}
        self.base_dir = base_dir or os.getcwd()
        self.warn = warn or (lambda message: print('xacro: warning: ' + message, file=sys.stderr))
        self.global_scope = _Scope()
        self.expansions = 0
        self.includes = 0
        self.include_stack = []
        self.macro_depth = 0
        self.depth = 0
        self.property_depth = 0
        self.output_bytes = 0
        self.elements = 0
        self.files = {}
        self.packages = _Packages()
        self.anon = {}
        self.location = (None, None)
        self.interpreter = _Interpreter({})
        builtins = _make_builtins(self.interpreter)
        helpers = _Helpers('xacro', {
            'load_yaml': self._load_yaml, 'arg': self._arg, 'dotify': _dotify,
            'message': self._message, 'warning': self._warning, 'error': self._error,
            'fatal': self._fatal, 'print_location': lambda *a, **k: '',
            'tokenize': _tokenize, 'abs_filename': self._abs_filename,
        })
        builtins['xacro'] = helpers
        builtins['load_yaml'] = self._load_yaml
        self.interpreter.builtins = builtins

    # files
    def load(self, path):
        real = os.path.realpath(path)
        try:
            info = os.stat(real)
        except OSError as error:
            raise XacroError('cannot read: %s' % error.strerror, path) from None
        key = (real, info.st_mtime_ns, info.st_size)
        root = self.files.get(key)
        if root is None:
            data = _read_limited(path)
            root = _parse_xml(data, path)
            self.files[key] = root
        return root

    def expand(self, root, source_name):
        if root.xname is not None:
            raise XacroError('the root element cannot be a xacro element', root.file, root.line,
                             '<%s>' % root.tag)
        limit = sys.getrecursionlimit()
        sys.setrecursionlimit(max(limit, 20000))
        try:
            out = _Out(root.tag)
            self._attributes(root, self.global_scope, out)
            self._nodes(root.children, self.global_scope, out)
            text = _serialize(out, source_name)
        except RecursionError:
            raise XacroError('the description nests too deeply', root.file) from None
        except MemoryError:
            raise XacroError('out of memory expanding the description', root.file) from None
        finally:
            sys.setrecursionlimit(limit)
        if len(text) > limits.MAX_OUTPUT_BYTES:
            raise XacroError('the output is larger than %d bytes' % limits.MAX_OUTPUT_BYTES,
                             root.file)
        return text

    # output accounting
    def _charge_output(self, count):
        self.output_bytes += count
        if self.output_bytes > limits.MAX_OUTPUT_BYTES:
            raise _EvalError('the output would be larger than %d bytes' % limits.MAX_OUTPUT_BYTES)

    def _count_element(self, node):
        self.elements += 1
        if self.elements > limits.MAX_ELEMENTS:
            raise XacroError('the output would have more than %d elements' % limits.MAX_ELEMENTS,
                             node.file, node.line, '<%s>' % node.tag)

    def _enter(self, node):
        self.depth += 1
        if self.depth > limits.MAX_DEPTH:
            raise XacroError('elements, macro calls and includes nest more than %d deep'
                             % limits.MAX_DEPTH, node.file, node.line, '<%s>' % node.tag)

    # the walk
    def _nodes(self, nodes, scope, out):
        # Comments right before a definition (macro, property, arg, include)
        # describe it and go with it; others are kept.
        held = []
        for node in nodes:
            kind = type(node)
            if kind is _Comment:
                held.append(_OutComment(node.text))
                continue
            if kind is _Text:
                if held and not node.text.strip():
                    continue
            elif held and node.xname in _DEFINITIONS:
                held = []
            if held:
                out.children.extend(held)
                held = []
            if kind is _Text:
                text = node.text
                if '$' in text:
                    text = self.text_value(text, scope, node.file, node.line)
                if text:
                    self._add_text(out, text, node)
            elif node.xname is None:
                self._plain(node, scope, out)
            else:
                self._directive(node, scope, out)
        out.children.extend(held)

    def _add_text(self, out, text, node):
        try:
            self._charge_output(len(text))
        except _EvalError as error:
            raise XacroError(str(error), node.file, node.line) from None
        if out.children and isinstance(out.children[-1], str):
            out.children[-1] += text
        else:
            out.children.append(text)

    def _skip_attribute(self, node, name):
        prefix, _, local = name.rpartition(':')
        if prefix == 'xmlns':
            return local in node.xprefixes
        return bool(prefix) and prefix in node.xprefixes

    def _attributes(self, node, scope, out, skip=()):
        for name, raw in node.attrs:
            if name in skip or self._skip_attribute(node, name):
                continue
            value = self.text_value(raw, scope, node.file, node.line) if '$' in raw else raw
            self._check_output(value, node, '<%s %s>' % (node.tag, name))
            out.attrs[name] = value

    def _check_output(self, value, node, construct):
        bad = _BAD_XML_CHARS.search(value)
        if bad:
            raise XacroError('the value has a character XML cannot hold (U+%04X)'
                             % ord(bad.group()), node.file, node.line, construct)
        try:
            self._charge_output(len(value) + 4)
        except _EvalError as error:
            raise XacroError(str(error), node.file, node.line, construct) from None

    def _plain(self, node, scope, out):
        self._enter(node)
        try:
            element = _Out(node.tag)
            self._count_element(node)
            self._check_output(node.tag, node, '<%s>' % node.tag)
            self._attributes(node, scope, element)
            out.children.append(element)
            self._nodes(node.children, scope, element)
        finally:
            self.depth -= 1

    def _directive(self, node, scope, out):
        name = node.xname
        if name == 'property':
            self._property(node, scope)
        elif name == 'arg':
            self._define_arg(node, scope)
        elif name == 'macro':
            self._define_macro(node, scope)
        elif name == 'include':
            self._include(node, scope, out)
        elif name in ('if', 'unless'):
            raw = self._required(node, 'value')
            value = self.value(raw, scope, node.file, node.line)
            try:
                condition = _to_bool(value)
            except _EvalError as error:
                raise XacroError('value %r is %r, %s' % (raw, value, error), node.file,
                                 node.line, '<%s>' % node.tag) from None
            if condition == (name == 'if'):
                self._nodes(node.children, scope, out)
        elif name == 'insert_block':
            self._insert_block(node, scope, out)
        elif name == 'element':
            self._element(node, scope, out)
        elif name == 'attribute':
            attribute = self._string(self._required(node, 'name'), scope, node)
            if not _XML_NAME.match(attribute):
                raise XacroError('%r is not an XML attribute name' % attribute, node.file,
                                 node.line, '<%s>' % node.tag)
            value = self._string(self._required(node, 'value'), scope, node)
            self._check_output(value, node, '<%s>' % node.tag)
            if out.tag is not None:
                out.attrs[attribute] = value
        elif name == 'call':
            macro = self._string(self._required(node, 'macro'), scope, node)
            self._call(node, scope, out, macro, skip=('macro',))
        else:
            self._call(node, scope, out, name)

    def _required(self, node, attribute):
        value = node.get(attribute)
        if value is None:
            raise XacroError("missing attribute '%s'" % attribute, node.file, node.line,
                             '<%s>' % node.tag)
        return value

    def _string(self, raw, scope, node):
        value = self.value(raw, scope, node.file, node.line)
        return value if isinstance(value, str) else str(value)

    # properties and args
    def _property(self, node, scope):
        construct = '<%s>' % node.tag
        name = self._required(node, 'name').strip()
        if not name.isidentifier() or keyword.iskeyword(name) or name.startswith('__'):
            raise XacroError("property name '%s' is not a Python identifier (or starts with '__')"
                             % name, node.file, node.line, construct)
        where = node.get('scope')
        if where in (None, '', 'local'):
            target = scope
        elif where == 'parent':
            target = scope.parent or self.global_scope
        elif where == 'global':
            target = self.global_scope
        else:
            raise XacroError("scope '%s' is neither 'parent' nor 'global'" % where, node.file,
                             node.line, construct)
        remove = node.get('remove')
        if remove is not None and _to_bool(self.value(remove, scope, node.file, node.line)):
            target.props.pop(name, None)
            return
        raw = node.get('value')
        default = node.get('default')
        if raw is None and default is None:
            target.props[name] = _Prop(name, _Block(node.children, False), file=node.file,
                                       line=node.line)
            return
        if raw is None:
            if target.find_prop(name) is not None:
                return
            raw = default
        lazy = node.get('lazy_eval')
        lazy = True if lazy is None else _to_bool(self.value(lazy, scope, node.file, node.line))
        if lazy and target is scope and '$' in raw:
            target.props[name] = _Prop(name, raw=raw, scope=scope, file=node.file, line=node.line)
        else:
            value = _literal(self.value(raw, scope, node.file, node.line))
            target.props[name] = _Prop(name, value, file=node.file, line=node.line)

    def resolve(self, name, prop):
        if prop.state == _Prop.DONE:
            value = prop.value
            if isinstance(value, _Block):
                raise _EvalError("property '%s' is a block: insert it with "
                                 "<xacro:insert_block name=\"%s\"/>" % (name, name))
            return value
        if prop.state == _Prop.BUSY:
            raise XacroError("circular definition of property '%s'" % name, prop.file, prop.line,
                             '<xacro:property name="%s">' % name)
        prop.state = _Prop.BUSY
        self.property_depth += 1
        try:
            if self.property_depth > limits.MAX_PROPERTY_DEPTH:
                raise XacroError('properties refer to properties more than %d deep'
                                 % limits.MAX_PROPERTY_DEPTH, prop.file, prop.line)
            value = _literal(self.value(prop.raw, prop.scope, prop.file, prop.line))
        except BaseException:
            prop.state = _Prop.RAW
            raise
        finally:
            self.property_depth -= 1
        prop.value = value
        prop.raw = None
        prop.scope = None
        prop.state = _Prop.DONE
        return value

    def _define_arg(self, node, scope):
        name = self._required(node, 'name').strip()
        default = node.get('default')
        if name in self.args or name in self.arg_defaults or default is None:
            return
        self.arg_defaults[name] = self._string(default, scope, node)

    def _arg(self, name):
        if name in self.args:
            return self.args[name]
        if name in self.arg_defaults:
            return self.arg_defaults[name]
        raise _EvalError("undefined substitution argument '%s' (give it as %s:=VALUE or "
                         "declare <xacro:arg name=\"%s\" default=\"...\"/>)" % (name, name, name))

    # xacro:element
    def _element(self, node, scope, out):
        construct = '<%s>' % node.tag
        name_attribute = None
        for attribute, _ in node.attrs:
            prefix, _, local = attribute.rpartition(':')
            if local == 'name' and prefix in node.xprefixes:
                name_attribute = attribute
        if name_attribute is None:
            raise XacroError("missing attribute 'xacro:name'", node.file, node.line, construct)
        tag = self._string(node.get(name_attribute), scope, node)
        if not _XML_NAME.match(tag):
            raise XacroError('%r is not an XML element name' % tag, node.file, node.line,
                             construct)
        self._enter(node)
        try:
            element = _Out(tag)
            self._count_element(node)
            self._check_output(tag, node, construct)
            self._attributes(node, scope, element, skip=(name_attribute,))
            out.children.append(element)
            self._nodes(node.children, scope, element)
        finally:
            self.depth -= 1

    # includes
    def _include(self, node, scope, out):
        construct = '<%s>' % node.tag
        filename = self._string(self._required(node, 'filename'), scope, node).strip()
        namespace = node.get('ns')
        if namespace is not None:
            namespace = self._string(namespace, scope, node).strip()
            if not namespace.isidentifier() or namespace.startswith('_'):
                raise XacroError("ns '%s' is not a Python identifier" % namespace, node.file,
                                 node.line, construct)
        base = os.path.dirname(os.path.abspath(node.file)) if _is_real_file(node.file) \
            else self.base_dir
        path = filename if os.path.isabs(filename) else os.path.join(base, filename)
        path = os.path.normpath(path)
        if any(c in filename for c in '*?['):
            paths = sorted(glob.glob(path))
            if not paths:
                self.warn('%s:%s: include pattern %s matches no file' % (node.file, node.line,
                                                                      filename))
        else:
            if not os.path.isfile(path):
                raise XacroError("missing include file '%s' (%s)" % (filename, path), node.file,
                                 node.line, construct)
            paths = [path]
        target = scope
        if namespace:
            existing = scope.props.get(namespace)
            if existing is not None and isinstance(existing.value, _Namespace):
                target = existing.value._scope
            else:
                target = _Scope(parent=scope)
                scope.props[namespace] = _Prop(namespace, _Namespace(namespace, target, self))
                scope.macros[namespace] = _MacroNamespace(target)
        for one in paths:
            self.includes += 1
            if self.includes > limits.MAX_INCLUDES:
                raise XacroError('more than %d includes: the work is bounded'
                                 % limits.MAX_INCLUDES, node.file, node.line, construct)
            if len(self.include_stack) >= limits.MAX_INCLUDE_DEPTH:
                raise XacroError('includes nest more than %d deep (does %s include itself?)'
                                 % (limits.MAX_INCLUDE_DEPTH, os.path.basename(one)), node.file,
                                 node.line, construct)
            self.include_stack.append(one)
            self._enter(node)
            try:
                try:
                    root = self.load(one)
                except XacroError as error:
                    error.trace.append('included from %s:%s' % (node.file, node.line))
                    raise
                try:
                    self._nodes(root.children, target, out)
                except XacroError as error:
                    error.trace.append('included from %s:%s' % (node.file, node.line))
                    raise
            finally:
                self.include_stack.pop()
                self.depth -= 1
