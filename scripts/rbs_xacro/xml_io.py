"""XML in and out: the input tree with file and line numbers (expat), the
output tree and its serialisation, reading a file within its size bound, and
telling xacro from plain XML."""

import os
import re
import xml.parsers.expat as expat

from . import limits
from .errors import XacroError

_XACRO_URI = re.compile(r'^\s*https?://(www\.|wiki\.)?ros\.org/(wiki/)?xacro/?\s*$')
_XML_NAME = re.compile(r'^[A-Za-z_][\w.\-]*(:[A-Za-z_][\w.\-]*)?$')
_BAD_XML_CHARS = re.compile('[\x00-\x08\x0b\x0c\x0e-\x1f\ud800-\udfff\ufffe\uffff]')


# --- the input tree -------------------------------------------------------------

class _Element:
    __slots__ = ('tag', 'attrs', 'children', 'file', 'line', 'xname', 'xprefixes')

    def __init__(self, tag, attrs, file, line, xname, xprefixes):
        self.tag = tag
        self.attrs = attrs          # [(name, value)] in document order
        self.children = []
        self.file = file
        self.line = line
        self.xname = xname          # local name of a xacro element, else None
        self.xprefixes = xprefixes  # prefixes that mean xacro here

    def get(self, name, default=None):
        for key, value in self.attrs:
            if key == name:
                return value
        return default


class _Text:
    __slots__ = ('text', 'file', 'line')

    def __init__(self, text, file, line):
        self.text = text
        self.file = file
        self.line = line


class _Comment:
    __slots__ = ('text',)

    def __init__(self, text):
        self.text = text


def _is_xacro_uri(uri):
    return bool(_XACRO_URI.match(uri))


class _TreeBuilder:
    """expat's handlers, building the _Element tree of one file."""

    def __init__(self, filename):
        self.filename = filename
        self.parser = parser = expat.ParserCreate()
        parser.ordered_attributes = True
        parser.buffer_text = False
        self.stack = []    # (element, {prefix: uri})
        self.roots = []
        self.pending = []  # text chunks not yet in a _Text
        self.pending_line = 0
        self.prefix_sets = {}
        self.count = 0
        parser.StartElementHandler = self.start
        parser.EndElementHandler = self.end
        parser.CharacterDataHandler = self.characters
        parser.CommentHandler = self.comment
        parser.EntityDeclHandler = self.entity_declaration
        parser.ExternalEntityRefHandler = self.external_entity
        parser.SetParamEntityParsing(expat.XML_PARAM_ENTITY_PARSING_NEVER)

    def flush(self):
        if self.pending and self.stack:
            self.stack[-1][0].children.append(_Text(''.join(self.pending), self.filename,
                                                    self.pending_line))
        del self.pending[:]

    def start(self, tag, attribute_list):
        self.flush()
        stack, line = self.stack, self.parser.CurrentLineNumber
        attrs = list(zip(attribute_list[0::2], attribute_list[1::2]))
        namespaces = stack[-1][1] if stack else {}
        declared = [(name[6:], value) for name, value in attrs if name.startswith('xmlns:')]
        if declared:
            namespaces = dict(namespaces)
            namespaces.update(declared)
        key = frozenset(prefix for prefix, uri in namespaces.items() if _is_xacro_uri(uri))
        xprefixes = self.prefix_sets.setdefault(key, key | {'xacro'})
        prefix, _, local = tag.rpartition(':')
        element = _Element(tag, attrs, self.filename, line,
                           local if prefix and prefix in xprefixes else None, xprefixes)
        self.count += 1
        if self.count > limits.MAX_ELEMENTS:
            raise XacroError('more than %d elements in the file' % limits.MAX_ELEMENTS,
                             self.filename, line, '<%s>' % tag)
        if len(stack) >= limits.MAX_NESTING:
            raise XacroError('elements nested more than %d deep' % limits.MAX_NESTING,
                             self.filename, line, '<%s>' % tag)
        if stack:
            stack[-1][0].children.append(element)
        else:
            self.roots.append(element)
        stack.append((element, namespaces))

    def end(self, tag):
        self.flush()
        self.stack.pop()

    def characters(self, data):
        if not self.pending:
            self.pending_line = self.parser.CurrentLineNumber
        self.pending.append(data)

    def comment(self, data):
        self.flush()
        if self.stack:
            self.stack[-1][0].children.append(_Comment(data))

    def entity_declaration(self, *_):
        raise XacroError('entity declarations are not supported', self.filename,
                         self.parser.CurrentLineNumber, '<!ENTITY>')

    def external_entity(self, *_):
        raise XacroError('external entities are not supported', self.filename,
                         self.parser.CurrentLineNumber)


def _parse_xml(data, filename):
    """The root _Element of `data` (bytes or str), with line numbers."""
    builder = _TreeBuilder(filename)
    try:
        builder.parser.Parse(data, True)
    except expat.ExpatError as error:
        raise XacroError('not well-formed XML: %s' % expat.ErrorString(error.code), filename,
                         error.lineno) from None
    if not builder.roots:
        raise XacroError('no root element', filename)
    return builder.roots[0]


# --- the output tree ---------------------------------------------------------------

class _Out:
    __slots__ = ('tag', 'attrs', 'children')

    def __init__(self, tag):
        self.tag = tag
        self.attrs = {}
        self.children = []   # _Out, str (text) or _OutComment


class _OutComment:
    __slots__ = ('text',)

    def __init__(self, text):
        self.text = text


def _escape_text(text):
    return text.replace('&', '&amp;').replace('<', '&lt;').replace('>', '&gt;')


def _escape_attribute(text):
    return (_escape_text(text).replace('"', '&quot;').replace('\n', '&#10;')
            .replace('\r', '&#13;').replace('\t', '&#9;'))


def _serialize(root, source_name):
    lines = ['<?xml version="1.0" ?>']
    if source_name:
        lines.append('<!-- Generated by rigid_body_sim\'s xacro from %s; edit that file '
                     'instead. -->' % os.path.basename(source_name).replace('--', '- -'))

    def write(element, indent):
        attributes = ''.join(' %s="%s"' % (name, _escape_attribute(value))
                             for name, value in element.attrs.items())
        children = [child for child in element.children
                    if not (isinstance(child, str) and not child.strip())]
        if not children:
            lines.append('%s<%s%s/>' % (indent, element.tag, attributes))
        elif all(isinstance(child, str) for child in children):
            lines.append('%s<%s%s>%s</%s>' % (indent, element.tag, attributes,
                                              _escape_text(''.join(children).strip()),
                                              element.tag))
        else:
            lines.append('%s<%s%s>' % (indent, element.tag, attributes))
            inner = indent + '  '
            for child in children:
                if isinstance(child, _Out):
                    write(child, inner)
                elif isinstance(child, _OutComment):
                    lines.append('%s<!--%s-->' % (inner, child.text))
                else:
                    lines.append(inner + _escape_text(child.strip()))
            lines.append('%s</%s>' % (indent, element.tag))

    write(root, '')
    lines.append('')
    return '\n'.join(lines)


def _read_limited(path):
    try:
        with open(path, 'rb') as stream:
            data = stream.read(limits.MAX_FILE_BYTES + 1)
    except OSError as error:
        raise XacroError('cannot read: %s' % (error.strerror or error), path) from None
    if len(data) > limits.MAX_FILE_BYTES:
        raise XacroError('the file is larger than %d bytes' % limits.MAX_FILE_BYTES, path)
    return data


class _FoundRoot(Exception):
    pass


def is_xacro(text, path=None):
    """True when `path` ends in .xacro or the root element of `text` (str or
    bytes) declares the xacro namespace."""
    if path and str(path).endswith('.xacro'):
        return True
    parser = expat.ParserCreate()
    found = []

    def start(_, attributes):
        found.extend(value for name, value in attributes.items()
                     if name.startswith('xmlns') and _is_xacro_uri(value))
        raise _FoundRoot()

    parser.StartElementHandler = start
    try:
        parser.Parse(text, True)
    except _FoundRoot:
        pass
    except expat.ExpatError:
        return False
    return bool(found)
