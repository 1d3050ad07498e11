#!/usr/bin/env python3
"""scripts/xacro and its package scripts/rbs_xacro, our own xacro expander:
each construct of the xacro language on a small input against its URDF
expanded by hand, the errors (file, line, construct), the bounds on hostile
input, the command line, and a two-link arm shaped like the real
descriptions (test/data/xacro/packages).

Plain unittest, no ROS master:  python3 test/xacro/xacro_test.py
"""

import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import unittest
import xml.etree.ElementTree as ElementTree

HERE = os.path.dirname(os.path.realpath(__file__))
SOURCE = os.path.dirname(os.path.dirname(HERE))
SCRIPT = os.path.join(SOURCE, 'scripts', 'xacro')
DATA = os.path.join(SOURCE, 'test', 'data', 'xacro')
PACKAGES = os.path.join(DATA, 'packages')
NS = 'xmlns:xacro="http://www.ros.org/wiki/xacro"'


def load_xacro():
    """The expander package (scripts/rbs_xacro), imported as scripts/xacro
    imports it."""
    sys.path.insert(0, os.path.join(SOURCE, 'scripts'))
    saved, sys.dont_write_bytecode = sys.dont_write_bytecode, True
    try:  # no __pycache__ beside the sources
        import rbs_xacro
    finally:
        sys.dont_write_bytecode = saved
    return rbs_xacro


xacro = load_xacro()


def robot(body, name='r'):
    return '<?xml version="1.0"?>\n<robot name="%s" %s>\n%s\n</robot>\n' % (name, NS, body)


def _numbers_equal(expected, actual):
    try:
        e, a = float(expected), float(actual)
    except ValueError:
        return False
    return math.isclose(e, a, rel_tol=1e-12, abs_tol=1e-300) or (math.isnan(e) and math.isnan(a))


def _same_value(expected, actual):
    """Whitespace-separated words equal, numbers as floats within 1e-12."""
    expected_words, actual_words = expected.split(), actual.split()
    if len(expected_words) != len(actual_words):
        return False
    return all(e == a or _numbers_equal(e, a) for e, a in zip(expected_words, actual_words))


def tree_difference(expected, actual, path=''):
    """None when the element trees match (names, attributes, children in
    order, text; comments and whitespace ignored), else where they differ."""
    here = '%s/%s' % (path, expected.tag)
    if expected.tag != actual.tag:
        return '%s: element <%s> expected, <%s> found' % (path or '/', expected.tag, actual.tag)
    if set(expected.attrib) != set(actual.attrib):
        return '%s: attributes %s expected, %s found' % (here, sorted(expected.attrib),
                                                         sorted(actual.attrib))
    for key, value in expected.attrib.items():
        if not _same_value(value, actual.attrib[key]):
            return '%s@%s: %r expected, %r found' % (here, key, value, actual.attrib[key])
    if not _same_value(expected.text or '', actual.text or ''):
        return '%s: text %r expected, %r found' % (here, expected.text, actual.text)
    expected_children, actual_children = list(expected), list(actual)
    if len(expected_children) != len(actual_children):
        return '%s: %d children expected (%s), %d found (%s)' % (
            here, len(expected_children), ' '.join(c.tag for c in expected_children),
            len(actual_children), ' '.join(c.tag for c in actual_children))
    for index, (e, a) in enumerate(zip(expected_children, actual_children)):
        difference = tree_difference(e, a, '%s[%d]' % (here, index))
        if difference:
            return difference
        if not _same_value(e.tail or '', a.tail or ''):
            return '%s: text after <%s> %r expected, %r found' % (here, e.tag, e.tail, a.tail)
    return None


class XacroTestCase(unittest.TestCase):

    @classmethod
    def setUpClass(cls):
        cls._saved_path = os.environ.get('ROS_PACKAGE_PATH')
        os.environ['ROS_PACKAGE_PATH'] = PACKAGES

    @classmethod
    def tearDownClass(cls):
        if cls._saved_path is None:
            os.environ.pop('ROS_PACKAGE_PATH', None)
        else:
            os.environ['ROS_PACKAGE_PATH'] = cls._saved_path

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix='xacro_test_')
        self.warnings = []

    def tearDown(self):
        shutil.rmtree(self.tmp, ignore_errors=True)

    def write(self, name, text):
        path = os.path.join(self.tmp, name)
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, 'w', encoding='utf-8') as stream:
            stream.write(text)
        return path

    def expand(self, body, args=None, **kwargs):
        return xacro.expand_string(robot(body), args or {}, warn=self.warnings.append, **kwargs)

    def assertXml(self, expected, actual):
        try:
            actual_root = ElementTree.fromstring(actual)
        except ElementTree.ParseError as error:
            self.fail('output is not XML (%s):\n%s' % (error, actual))
        difference = tree_difference(ElementTree.fromstring(expected), actual_root)
        if difference:
            self.fail('%s\n--- output:\n%s' % (difference, actual))

    def assertExpands(self, body, expected_body, args=None, **kwargs):
        self.assertXml('<robot name="r">%s</robot>' % expected_body,
                       self.expand(body, args, **kwargs))

    def assertError(self, pattern, body=None, args=None, path=None):
        """The expansion fails with a XacroError whose text matches `pattern`."""
        with self.assertRaises(xacro.XacroError) as caught:
            if path is not None:
                xacro.expand_file(path, args or {}, warn=self.warnings.append)
            else:
                self.expand(body, args)
        self.assertRegex(str(caught.exception), pattern)
        return caught.exception


class ComparisonTest(unittest.TestCase):
    """The test's own tree comparison."""

    def test_numbers_compare_as_floats_and_whitespace_is_ignored(self):
        self.assertIsNone(tree_difference(
            ElementTree.fromstring('<a x="1  0.5"><b>2</b></a>'),
            ElementTree.fromstring('<a x="1.0 0.50000000000000001">\n  <b> 2.0 </b>\n</a>')))
        self.assertIsNotNone(tree_difference(ElementTree.fromstring('<a x="1"/>'),
                                             ElementTree.fromstring('<a x="1.0001"/>')))
        self.assertIsNotNone(tree_difference(ElementTree.fromstring('<a><b/><c/></a>'),
                                             ElementTree.fromstring('<a><c/><b/></a>')))
        self.assertIsNotNone(tree_difference(ElementTree.fromstring('<a x="1"/>'),
                                             ElementTree.fromstring('<a x="1" y="2"/>')))


class PropertyTest(XacroTestCase):

    def test_value_properties_and_str_conversion(self):
        self.assertExpands(
            '<xacro:property name="width" value="0.2"/>'
            '<xacro:property name="count" value="3"/>'
            '<xacro:property name="label" value="arm"/>'
            '<a w="${width}" c="${count}" l="${label}" two="${2*width}" div="${count/2}"'
            ' fdiv="${count//2}" whole="${1.0}" int="${2*3}" mix="${label}_${count}"/>',
            '<a w="0.2" c="3" l="arm" two="0.4" div="1.5" fdiv="1" whole="1.0" int="6"'
            ' mix="arm_3"/>')
        # str() of the value, as xacro: 1.0 stays 1.0, 1 stays 1, booleans True/False
        out = self.expand('<xacro:property name="t" value="true"/>'
                          '<a x="${2*0.5}" y="${4/2}" z="${2}" t="${t}" n="${None}"/>')
        self.assertIn('<a x="1.0" y="2.0" z="2" t="True" n="None"/>', out)

    def test_properties_refer_to_properties_lazily(self):
        # b is used before c is defined: evaluation waits for the use.
        self.assertExpands(
            '<xacro:property name="b" value="${c * 2}"/>'
            '<xacro:property name="c" value="${d + 1}"/>'
            '<xacro:property name="d" value="1"/>'
            '<a b="${b}" c="${c}"/>',
            '<a b="4" c="2"/>')

    def test_lazy_eval_false_default_and_remove(self):
        self.assertExpands(
            '<xacro:property name="x" value="1"/>'
            '<xacro:property name="x" value="${x + 1}" lazy_eval="false"/>'
            '<xacro:property name="y" default="5"/>'
            '<xacro:property name="y" default="6"/>'
            '<xacro:property name="x" default="100"/>'
            '<a x="${x}" y="${y}"/>'
            '<xacro:property name="y" remove="true"/>'
            '<xacro:property name="y" default="7"/>'
            '<b y="${y}"/>',
            '<a x="2" y="5"/><b y="7"/>')

    def test_dict_list_number_and_string_values(self):
        self.assertExpands(
            '<xacro:property name="d" value="${dict(a=1, b=[2, 3])}"/>'
            '<xacro:property name="l" value="${[0.5, 1.5, \'z\']}"/>'
            '<xacro:property name="s" value="hello world"/>'
            '<xacro:property name="q" value="\'1.5\'"/>'
            '<xacro:property name="xyz" value="1 2 3"/>'
            '<a d="${d[\'b\'][1]}" l="${l[1] + l[0]}" z="${l[-1]}" s="${s.split()[1]}"'
            ' q="${q + \'0\'}" len="${len(l)}" sum="${sum(float(v) for v in xyz.split())}"'
            ' keys="${\' \'.join(sorted(d.keys()))}" cat="${s + \'!\'}"/>',
            '<a d="3" l="2.0" z="z" s="world" q="1.50" len="3" sum="6.0" keys="a b"'
            ' cat="hello world!"/>')

    def test_property_block_and_insert_block(self):
        self.assertExpands(
            '<xacro:property name="r" value="0.1"/>'
            '<xacro:property name="shape"><geometry><sphere radius="${r}"/></geometry>'
            '<origin xyz="0 0 ${r}"/></xacro:property>'
            '<link name="l"><visual><xacro:insert_block name="shape"/></visual>'
            '<collision><xacro:insert_block name="shape"/></collision></link>',
            '<link name="l"><visual><geometry><sphere radius="0.1"/></geometry>'
            '<origin xyz="0 0 0.1"/></visual><collision><geometry><sphere radius="0.1"/>'
            '</geometry><origin xyz="0 0 0.1"/></collision></link>')

    def test_macro_local_properties_and_parent_and_global_scope(self):
        self.assertExpands(
            '<xacro:property name="x" value="global"/>'
            '<xacro:macro name="inner">'
            '  <xacro:property name="x" value="inner-local"/>'
            '  <xacro:property name="from_inner" value="${x}!" scope="parent"/>'
            '  <xacro:property name="everywhere" value="g" scope="global"/>'
            '  <i x="${x}"/>'
            '</xacro:macro>'
            '<xacro:macro name="outer">'
            '  <xacro:inner/>'
            '  <o x="${x}" p="${from_inner}"/>'
            '</xacro:macro>'
            '<xacro:outer/>'
            '<top x="${x}" e="${everywhere}"/>',
            '<i x="inner-local"/><o x="global" p="inner-local!"/><top x="global" e="g"/>')
        # the macro's own property is gone after the call
        self.assertError(r"<t>: |\$\{from_inner\}: name 'from_inner' is not defined",
                         '<xacro:macro name="m"><xacro:property name="from_inner" value="1"/>'
                         '</xacro:macro><xacro:m/><t v="${from_inner}"/>')

    def test_circular_definition_is_an_error(self):
        self.assertError(r"circular definition of property 'a'",
                         '<xacro:property name="a" value="${b}"/>'
                         '<xacro:property name="b" value="${a}"/><x v="${a}"/>')


class ExpressionTest(XacroTestCase):

    def test_arithmetic_comparison_boolean_and_conditional_expressions(self):
        self.assertExpands(
            '<xacro:property name="n" value="7"/>'
            '<a add="${n + 1}" sub="${n - 10}" mul="${n * 2}" div="${n / 2}" mod="${n % 4}"'
            ' pow="${2 ** 10}" neg="${-n}" paren="${(n + 1) * 2}" lt="${n &lt; 8}"'
            ' ge="${n &gt;= 8}" eq="${n == 7}" ne="${n != 7}" and="${n &gt; 1 and n &lt; 9}"'
            ' or="${n &lt; 1 or n &gt; 9}" not="${not n}" in="${3 in [1, 2, 3]}"'
            ' cond="${\'big\' if n &gt; 5 else \'small\'}" chain="${1 &lt; n &lt; 10}"/>',
            '<a add="8" sub="-3" mul="14" div="3.5" mod="3" pow="1024" neg="-7" paren="16"'
            ' lt="True" ge="False" eq="True" ne="False" and="True" or="False" not="False"'
            ' in="True" cond="big" chain="True"/>')

    def test_math_functions_constants_and_builtins(self):
        values = {
            'pi': math.pi, 'sin(pi/6)': math.sin(math.pi / 6), 'cos(pi/3)': math.cos(math.pi / 3),
            'tan(pi/4)': math.tan(math.pi / 4), 'asin(0.5)': math.asin(0.5),
            'acos(0.5)': math.acos(0.5), 'atan(1)': math.atan(1), 'atan2(1, -1)': math.atan2(1, -1),
            'sqrt(2)': math.sqrt(2), 'radians(90)': math.pi / 2, 'degrees(pi)': 180.0,
            'floor(2.7)': 2, 'ceil(2.1)': 3, 'fabs(-1.5)': 1.5, 'pow(2, 0.5)': 2 ** 0.5,
            'log(e)': 1.0, 'log(8, 2)': 3.0, 'exp(1)': math.e, 'abs(-3)': 3, 'min(3, 1, 2)': 1,
            'max([3, 1, 2])': 3, 'int(\'42\')': 42, 'int(2.9)': 2, 'float(\'2.5\')': 2.5,
            'round(2.567, 2)': 2.57, 'round(2.5)': 2, 'len(\'abc\')': 3,
            'math.pi / 2': math.pi / 2, 'e': math.e,
        }
        body = ''.join('<v expr="%s" value="${%s}"/>' % (key.replace("'", '&apos;'),
                                                        key.replace("'", '&apos;'))
                       for key in values)
        root = ElementTree.fromstring(self.expand(body))
        for element in root:
            expected = values[element.get('expr')]
            self.assertTrue(_numbers_equal(repr(float(expected)), element.get('value')),
                            '%s: %s expected, %s found' % (element.get('expr'), expected,
                                                           element.get('value')))
        self.assertExpands(
            '<a s="${str(1.5) + \'m\'}" l="${list(\'ab\')}" d="${dict(a=1)}"'
            ' b1="${bool(0)}" b2="${bool(\'x\')}" i="${int(\'7\') + 1}"'
            ' comp="${[i * i for i in range(4) if i != 2]}" fs="${f\'{3.14159:.2f}\'}"'
            ' under="${[0 for _ in range(2)]}"'
            ' fmt="${\'{}-{}\'.format(1, \'a\')}" up="${\'abc\'.upper()}"'
            ' lam="${(lambda x, y=2: x * y)(4)}" zip="${list(zip([1, 2], \'ab\'))}"/>',
            '<a s="1.5m" l="[\'a\', \'b\']" d="{\'a\': 1}" b1="False" b2="True" i="8"'
            ' comp="[0, 1, 9]" fs="3.14" under="[0, 0]" fmt="1-a" up="ABC" lam="8"'
            ' zip="[(1, \'a\'), (2, \'b\')]"/>')

    def test_dollar_dollar_escapes_and_text_content(self):
        self.assertExpands(
            '<xacro:property name="a" value="1"/>'
            '<t v="$${a} $$(arg x) $5 ${a}">text ${a + 1} $${b} done</t>',
            '<t v="${a} $(arg x) $5 1">text 2 ${b} done</t>')

    def test_expressions_are_restricted(self):
        for expression, why in [
                ('().__class__', "attribute '__class__' is not allowed"),
                ('__import__("os")', "name '__import__' is not allowed"),
                ('_private', "name '_private' is not defined"),
                ('[__x for __x in (1,)]', "name '__x' is not allowed"),
                ('open("/etc/passwd")', "name 'open' is not defined"),
                ('eval("1")', "name 'eval' is not defined"),
                ('"{0.__class__}".format(1)', 'may only name or number an argument'),
                ('(1).__add__(2)', "attribute '__add__' is not allowed"),
                ('[x for x in ().__class__.__mro__]', "attribute '__class__' is not allowed"),
                ('"abc".encode', "has no attribute 'encode' that expressions may use"),
                ('str.format', "has no attribute 'format'"),
        ]:
            self.assertError(re.escape(why), '<x v="${%s}"/>' % expression.replace('"', '&quot;'))

    def test_undefined_name_names_file_line_and_expression(self):
        path = self.write('arm.urdf.xacro', robot(
            '  <xacro:property name="t" value="2"/>\n'
            '  <link name="a"/>\n'
            '  <link name="b"/>\n'
            '  <joint name="j" type="fixed">\n'
            '    <origin xyz="0 0 ${s * 2}"/>\n'
            '  </joint>'))
        error = self.assertError(r"arm\.urdf\.xacro:7: \$\{s \* 2\}: name 's' is not defined",
                                 path=path)
        self.assertEqual(7, error.line)
        self.assertTrue(error.file.endswith('arm.urdf.xacro'))
        self.assertEqual('${s * 2}', error.construct)

    def test_error_in_text_content_names_its_line(self):
        path = self.write('text.xacro', robot('<a>\n\n  ok ${1/0}\n</a>'))
        self.assertError(r"text\.xacro:5: \$\{1/0\}: ZeroDivisionError: division by zero",
                         path=path)

    def test_unbalanced_brace_is_an_error(self):
        path = self.write('unbalanced.xacro', robot('<a v="${1 + (2"/>'))
        self.assertError(r"unbalanced\.xacro:3: \$\{1 \+ \(2: unbalanced '\$\{' "
                         r"\(no closing '\}'\)", path=path)
        self.assertError(r"unbalanced '\$\(' \(no closing '\)'\)", '<a v="$(arg x"/>')

    def test_syntax_error(self):
        self.assertError(r"\$\{1 \+\}: invalid expression", '<a v="${1 +}"/>')


class SubstitutionTest(XacroTestCase):

    def test_arg_with_default_and_command_line_override(self):
        body = ('<xacro:arg name="name" default="base"/>'
                '<xacro:arg name="scale" default="2"/>'
                '<link name="$(arg name)_link" s="${$(arg scale) * 2}" t="${\'$(arg name)\'}"/>')
        self.assertExpands(body, '<link name="base_link" s="4" t="base"/>')
        self.assertExpands(body, '<link name="top_link" s="1.0" t="top"/>',
                           args={'name': 'top', 'scale': '0.5'})
        self.assertError(r"\$\(arg nothing\): undefined substitution argument 'nothing'",
                         '<a v="$(arg nothing)"/>')

    def test_find_env_optenv_eval_and_dirname(self):
        os.environ['XACRO_TEST_VARIABLE'] = 'from_env'
        os.environ.pop('XACRO_TEST_UNSET', None)
        try:
            self.assertExpands(
                '<xacro:arg name="n" default="3"/>'
                '<a find="$(find fake_common)" env="$(env XACRO_TEST_VARIABLE)"'
                ' opt1="$(optenv XACRO_TEST_VARIABLE fallback)"'
                ' opt2="$(optenv XACRO_TEST_UNSET fall back)" opt3="$(optenv XACRO_TEST_UNSET)"'
                ' eval="$(eval 2 * int(n) + 1)" eval2="$(eval arg(\'n\') + \'x\')"'
                ' dir="$(dirname)"/>',
                '<a find="%s" env="from_env" opt1="from_env" opt2="fall back" opt3=""'
                ' eval="7" eval2="3x" dir="%s"/>'
                % (os.path.join(PACKAGES, 'fake_common'), self.tmp),
                base_dir=self.tmp)
            self.assertError(r"\$\(env XACRO_TEST_UNSET\): environment variable "
                             r"'XACRO_TEST_UNSET' is not set", '<a v="$(env XACRO_TEST_UNSET)"/>')
            self.assertError(r"\$\(find no_such_package\): package 'no_such_package' not found",
                             '<a v="$(find no_such_package)"/>')
            self.assertError(r"unknown substitution '\$\(bogus", '<a v="$(bogus x)"/>')
        finally:
            del os.environ['XACRO_TEST_VARIABLE']

    def test_own_package_search_stops_descending_into_a_package(self):
        self.assertEqual(os.path.join(PACKAGES, 'fake_arm_description'),
                         xacro.find_package('fake_arm_description', [PACKAGES]))
        self.assertEqual(os.path.join(PACKAGES, 'fake_common'),
                         xacro.find_package('fake_common', [PACKAGES]))
        # fake_nested lies inside fake_common: not searched, as rospack does.
        self.assertIsNone(xacro.find_package('fake_nested', [PACKAGES]))
        self.assertEqual(os.path.join(PACKAGES, 'fake_common', 'xacro', 'nested_pkg'),
                         xacro.find_package('fake_nested',
                                            [os.path.join(PACKAGES, 'fake_common', 'xacro')]))
        self.assertIsNone(xacro.find_package('fake_common', [self.tmp]))


class IncludeTest(XacroTestCase):

    def test_relative_includes_twice_and_dirname(self):
        sub = os.path.join(DATA, 'include', 'sub')
        self.assertXml(
            '<robot name="inc"><link name="grandchild"/><link name="child_1_in_%s"/>'
            '<link name="grandchild"/><link name="child_2_in_%s"/><link name="main_2"/></robot>'
            % (sub, sub),
            xacro.expand_file(os.path.join(DATA, 'include', 'main.xacro'), {}))

    def test_include_through_find_with_namespace(self):
        self.assertExpands(
            '<xacro:include filename="$(find fake_common)/xacro/common.xacro" ns="c"/>'
            '<xacro:c.gazebo_material link="l" colour="Red"/>'
            '<p v="${c.ns_name}" w="${c[\'friction\']}"/>',
            '<gazebo reference="l"><material>Gazebo/Red</material><mu1>0.8</mu1></gazebo>'
            '<p v="arm" w="0.8"/>')
        # without ns, the names land in the including scope
        self.assertExpands(
            '<xacro:include filename="$(find fake_common)/xacro/common.xacro"/>'
            '<p v="${ns_name}"/>',
            '<p v="arm"/>')

    def test_include_relative_to_base_dir_and_glob(self):
        self.write('parts/a.xacro', robot('<link name="a"/>'))
        self.write('parts/b.xacro', robot('<link name="b"/>'))
        self.assertExpands('<xacro:include filename="parts/b.xacro"/>'
                           '<xacro:include filename="parts/*.xacro"/>',
                           '<link name="b"/><link name="a"/><link name="b"/>', base_dir=self.tmp)

    def test_missing_include_file(self):
        path = self.write('top.xacro', robot('\n<xacro:include filename="nowhere.xacro"/>'))
        self.assertError(r"top\.xacro:4: <xacro:include>: missing include file 'nowhere\.xacro'",
                         path=path)

    def test_error_in_an_included_file_names_that_file(self):
        self.write('child.xacro', robot('<a v="${oops}"/>'))
        path = self.write('parent.xacro', robot('<xacro:include filename="child.xacro"/>'))
        error = self.assertError(r"child\.xacro:3: \$\{oops\}: name 'oops' is not defined\n"
                                 r"  included from .*parent\.xacro:3", path=path)
        self.assertTrue(error.file.endswith('child.xacro'))

    def test_an_include_of_itself_is_bounded(self):
        path = self.write('self.xacro', robot('<xacro:include filename="self.xacro"/>'))
        self.assertError(r"includes nest more than \d+ deep", path=path)


class MacroTest(XacroTestCase):

    def test_parameters_with_defaults(self):
        self.assertExpands(
            '<xacro:macro name="m" params="name x:=1 y:=\'a b\' z:=${x * 2} w=3">'
            '<e n="${name}" x="${x}" y="${y}" z="${z}" w="${w}"/></xacro:macro>'
            '<xacro:m name="one"/><xacro:m name="two" x="5" y="c" w="${2 + 2}"/>',
            '<e n="one" x="1" y="a b" z="2" w="3"/><e n="two" x="5" y="c" z="10" w="4"/>')

    def test_multiline_params(self):
        self.assertExpands(
            '<xacro:macro name="m" params="\n   a\n   b:=2\n   c:=\'$(find fake_common)\'">'
            '<e a="${a}" b="${b}" c="${c}"/></xacro:macro><xacro:m a="1"/>',
            '<e a="1" b="2" c="%s"/>' % os.path.join(PACKAGES, 'fake_common'))

    def test_caret_takes_the_value_from_the_outer_scope(self):
        self.assertExpands(
            '<xacro:property name="mass" value="3"/>'
            '<xacro:macro name="m" params="mass:=^ colour:=^|red">'
            '<e m="${mass}" c="${colour}"/></xacro:macro>'
            '<xacro:m/><xacro:m mass="4"/>'
            '<xacro:property name="colour" value="green"/><xacro:m/>',
            '<e m="3" c="red"/><e m="4" c="red"/><e m="3" c="green"/>')
        self.assertError(r"<xacro:n>: macro 'n': parameter 'nothing' is to come from the calling "
                         r"scope \(\^\), which has no property 'nothing'",
                         '<xacro:macro name="n" params="nothing:=^"/><xacro:n/>')

    def test_block_parameters(self):
        self.assertExpands(
            '<xacro:macro name="caster" params="suffix *origin **content **more">'
            '<link name="caster_${suffix}"><xacro:insert_block name="origin"/>'
            '<xacro:insert_block name="content"/><xacro:insert_block name="more"/></link>'
            '</xacro:macro>'
            '<xacro:property name="m" value="0.1"/>'
            '<xacro:caster suffix="front">'
            '  <pose xyz="0 1 0"/>'
            '  <container><color name="yellow"/><mass>${m}</mass></container>'
            '  <another><inertial/></another>'
            '</xacro:caster>',
            '<link name="caster_front"><pose xyz="0 1 0"/><color name="yellow"/>'
            '<mass>0.1</mass><inertial/></link>')

    def test_blocks_pass_through_macros(self):
        self.assertExpands(
            '<xacro:macro name="inner" params="*o"><i><xacro:insert_block name="o"/></i>'
            '</xacro:macro>'
            '<xacro:macro name="outer" params="*origin">'
            '<xacro:inner><xacro:insert_block name="origin"/></xacro:inner></xacro:macro>'
            '<xacro:outer><origin xyz="1 2 3"/></xacro:outer>',
            '<i><origin xyz="1 2 3"/></i>')

    def test_nested_macros_and_macros_calling_macros(self):
        self.assertExpands(
            '<xacro:macro name="leaf" params="n"><leaf n="${n}"/></xacro:macro>'
            '<xacro:macro name="tree" params="prefix">'
            '  <xacro:macro name="branch" params="k">'
            '    <xacro:leaf n="${prefix}${k}"/>'
            '  </xacro:macro>'
            '  <xacro:branch k="1"/><xacro:branch k="2"/>'
            '</xacro:macro>'
            '<xacro:tree prefix="a"/>',
            '<leaf n="a1"/><leaf n="a2"/>')
        # the nested macro is the outer macro's own
        self.assertError(r"<xacro:branch>: unknown macro 'branch'",
                         '<xacro:macro name="tree"><xacro:macro name="branch"/></xacro:macro>'
                         '<xacro:tree/><xacro:branch/>')

    def test_recursion_with_a_condition_and_its_bound(self):
        self.assertExpands(
            '<xacro:macro name="chain" params="n">'
            '<l n="${n}"/><xacro:if value="${n &gt; 1}"><xacro:chain n="${n - 1}"/></xacro:if>'
            '</xacro:macro><xacro:chain n="3"/>',
            '<l n="3"/><l n="2"/><l n="1"/>')
        path = self.write('loop.xacro', robot(
            '<xacro:macro name="forever" params="n">\n'
            '  <xacro:forever n="${n + 1}"/>\n'
            '</xacro:macro>\n'
            '<xacro:forever n="0"/>'))
        error = self.assertError(r"loop\.xacro:4: <xacro:forever>: macro 'forever' calls macros "
                                 r"more than 100 deep", path=path)
        self.assertLess(len(str(error).splitlines()), 20)

    def test_expansion_count_is_bounded(self):
        self.assertError(r"more than 10000 macro expansions",
                         '<xacro:macro name="f" params="n"><xacro:if value="${n &lt; 20}">'
                         '<xacro:f n="${n+1}"/><xacro:f n="${n+1}"/></xacro:if></xacro:macro>'
                         '<xacro:f n="0"/>')

    def test_call_errors_name_the_file_line_and_macro(self):
        path = self.write('panda_arm.xacro', robot(
            '<xacro:macro name="panda_link" params="name colour:=white">\n'
            '  <link name="${name}"/>\n'
            '</xacro:macro>\n'
            '<xacro:panda_link name="a" color="red"/>\n'
            '<xacro:panda_link/>\n'
            '<xacro:panda_limb name="b"/>'))
        error = self.assertError(r"^.*panda_arm\.xacro:6: <xacro:panda_link>: macro 'panda_link' "
                                 r"has no parameter 'color'$", path=path)
        self.assertEqual((6, '<xacro:panda_link>'), (error.line, error.construct))
        self.write('panda_arm.xacro', robot(
            '<xacro:macro name="panda_link" params="name colour:=white"/>\n<xacro:panda_link/>'))
        self.assertError(r"panda_arm\.xacro:4: <xacro:panda_link>: macro 'panda_link' has no "
                         r"value for parameter 'name'", path=path)
        self.write('panda_arm.xacro', robot('\n<xacro:panda_limb name="b"/>'))
        self.assertError(r"panda_arm\.xacro:4: <xacro:panda_limb>: unknown macro 'panda_limb'",
                         path=path)

    def test_error_inside_a_macro_names_the_body_line_and_the_call(self):
        path = self.write('body.xacro', robot(
            '<xacro:macro name="m" params="a">\n'
            '  <e v="${a + b}"/>\n'
            '</xacro:macro>\n'
            '<xacro:m a="1"/>'))
        self.assertError(r"body\.xacro:4: \$\{a \+ b\}: name 'b' is not defined\n"
                         r"  in macro 'm' called at .*body\.xacro:6", path=path)

    def test_block_parameter_errors(self):
        self.assertError(r"macro 'm' takes block parameter '\*o', but the call has no child "
                         r"element left for it", '<xacro:macro name="m" params="*o"/><xacro:m/>')
        self.assertError(r"macro 'm' was given 1 child element\(s\) more than",
                         '<xacro:macro name="m" params="*o"/><xacro:m><a/><b/></xacro:m>')
        self.assertError(r"macro 'm' has no block parameters",
                         '<xacro:macro name="m"/><xacro:m><a/></xacro:m>')
        self.assertError(r"<xacro:insert_block>: undefined property 'nothing'",
                         '<a><xacro:insert_block name="nothing"/></a>')
        self.assertError(r"property 'p' is not a block",
                         '<xacro:property name="p" value="1"/><xacro:insert_block name="p"/>')


class ConditionalAndElementTest(XacroTestCase):

    def test_if_and_unless(self):
        self.assertExpands(
            '<xacro:property name="var" value="useit"/>'
            '<xacro:property name="allowed" value="${[1, 2, 3]}"/>'
            '<xacro:if value="true"><a n="1"/></xacro:if>'
            '<xacro:if value="false"><a n="2"/></xacro:if>'
            '<xacro:if value="1"><a n="3"/></xacro:if>'
            '<xacro:if value="0"><a n="4"/></xacro:if>'
            '<xacro:if value="${var == \'useit\'}"><a n="5"/></xacro:if>'
            '<xacro:if value="${var.startswith(\'use\') and var.endswith(\'it\')}"><a n="6"/>'
            '</xacro:if>'
            '<xacro:if value="${1 in allowed}"><a n="7"/></xacro:if>'
            '<xacro:unless value="false"><a n="8"/></xacro:unless>'
            '<xacro:unless value="${2 &gt; 1}"><a n="9"/></xacro:unless>'
            '<xacro:if value="True"><a n="10"/></xacro:if>',
            '<a n="1"/><a n="3"/><a n="5"/><a n="6"/><a n="7"/><a n="8"/><a n="10"/>')
        path = self.write('cond.xacro', robot('\n\n<xacro:if value="maybe"/>'))
        self.assertError(r"cond\.xacro:5: <xacro:if>: value 'maybe' is 'maybe', not a boolean",
                         path=path)

    def test_element_attribute_and_call(self):
        self.assertExpands(
            '<xacro:property name="tag" value="sphere"/>'
            '<xacro:macro name="ball" params="r"><xacro:element xacro:name="${tag}" radius="${r}"/>'
            '</xacro:macro>'
            '<geometry><xacro:call macro="${\'ba\' + \'ll\'}" r="0.5"/></geometry>'
            '<link><xacro:attribute name="name" value="${tag}_link"/>'
            '<xacro:element xacro:name="in${\'ertial\'}"><mass value="1"/></xacro:element></link>',
            '<geometry><sphere radius="0.5"/></geometry>'
            '<link name="sphere_link"><inertial><mass value="1"/></inertial></link>')


class YamlTest(XacroTestCase):

    def test_load_yaml_with_attribute_access_and_angle_tags(self):
        try:
            import yaml  # noqa: F401
        except ImportError:
            self.assertError(r'xacro\.load_yaml needs PyYAML',
                             '<a v="${xacro.load_yaml(\'x.yaml\')}"/>')
            return
        self.write('limits.yaml', 'joint:\n  lower: !degrees -90\n  upper: !radians pi / 4\n'
                                  '  names: [a, b]\n  effort: 10\n')
        self.assertExpands(
            '<xacro:property name="cfg" value="${xacro.load_yaml(\'limits.yaml\')}"/>'
            '<limit lower="${cfg.joint.lower}" upper="${cfg[\'joint\'][\'upper\']}"'
            ' effort="${cfg.joint.effort * 2}" n="${cfg.joint.names[1]}"'
            ' has="${\'joint\' in cfg}"/>',
            '<limit lower="%r" upper="%r" effort="20" n="b" has="True"/>'
            % (-math.pi / 2, math.pi / 4), base_dir=self.tmp)
        self.assertError(r"cannot load YAML file", '<a v="${xacro.load_yaml(\'none.yaml\')}"/>',
                         )


class NamespaceTest(XacroTestCase):

    def test_older_namespace_uris_and_gazebo_elements_pass(self):
        for uri in ('http://ros.org/wiki/xacro', 'http://wiki.ros.org/xacro',
                    'http://www.ros.org/wiki/xacro'):
            text = ('<robot name="r" xmlns:xacro="%s" xmlns:interface="http://playerstage.'
                    'sourceforge.net/gazebo/xmlschema/#interface">'
                    '<xacro:property name="a" value="1"/>'
                    '<gazebo reference="l"><mu1>${a}</mu1></gazebo>'
                    '<transmission name="t"><type>x</type></transmission></robot>' % uri)
            self.assertTrue(xacro.is_xacro(text))
            out = xacro.expand_string(text, {})
            self.assertNotIn('xmlns:xacro', out)
            self.assertIn('xmlns:interface', out)
            self.assertXml('<robot name="r"><gazebo reference="l"><mu1>1</mu1></gazebo>'
                           '<transmission name="t"><type>x</type></transmission></robot>', out)

    def test_other_prefix_bound_to_the_xacro_namespace(self):
        self.assertXml('<robot name="r"><a v="2"/></robot>', xacro.expand_string(
            '<robot name="r" xmlns:x="http://www.ros.org/wiki/xacro">'
            '<x:property name="p" value="2"/><a v="${p}"/></robot>', {}))

    def test_plain_urdf_passes_through_unchanged(self):
        text = '<?xml version="1.0"?>\n<robot name="r"><link name="${not_xacro}"/></robot>\n'
        self.assertFalse(xacro.is_xacro(text))
        self.assertEqual(text, xacro.expand_string(text, {}))
        path = self.write('plain.urdf', text)
        self.assertEqual(text, xacro.expand_file(path, {}))
        # a .xacro name makes it xacro even without the namespace
        path = self.write('bare.xacro', '<robot name="r"><xacro:property name="p" value="1"/>'
                                        '<link name="l${p}"/></robot>')
        self.assertXml('<robot name="r"><link name="l1"/></robot>', xacro.expand_file(path, {}))

    def test_malformed_xml_names_the_line(self):
        path = self.write('bad.xacro', robot('<link>\n</joint>'))
        self.assertError(r"bad\.xacro:4: not well-formed XML: mismatched tag", path=path)


class BoundsTest(XacroTestCase):

    def test_hostile_expressions_end_in_errors(self):
        for expression, why in [
                ('9**9**9', 'an integer of more than'),
                ('"x" * 10**9', 'a string longer than'),
                ('[0] * 10**7', 'a container of more than'),
                ('[i for i in range(10**6) for j in range(10**6)]', 'more than'),
                ('(lambda f: f(f))(lambda f: f(f))', 'lambdas call each other more than'),
                ('"%099999d" % 1', 'format width'),
                ('"{:>99999}".format(1)', 'format width'),
        ]:
            self.assertError(re.escape(why), '<x v="${%s}"/>' % expression.replace('"', '&quot;'))

    def test_output_size_and_element_count_are_bounded(self):
        saved = xacro.MAX_ELEMENTS, xacro.MAX_OUTPUT_BYTES
        xacro.MAX_ELEMENTS, xacro.MAX_OUTPUT_BYTES = 50, 4096
        try:
            self.assertError(r"the output would have more than 50 elements",
                             '<xacro:macro name="m" params="n"><e/><e/><xacro:if value="${n}">'
                             '<xacro:m n="${n-1}"/></xacro:if></xacro:macro><xacro:m n="40"/>')
            self.assertError(r"larger than 4096 bytes",
                             '<xacro:property name="s" value="${\'x\' * 1000}"/>'
                             '<a v="${s}"/><a v="${s}"/><a v="${s}"/><a v="${s}"/><a v="${s}"/>')
        finally:
            xacro.MAX_ELEMENTS, xacro.MAX_OUTPUT_BYTES = saved
        # doubling properties: 16 * 2**39 characters are never made
        body = '<xacro:property name="p0" value="xxxxxxxxxxxxxxxx"/>' + ''.join(
            '<xacro:property name="p%d" value="${p%d}${p%d}"/>' % (i, i - 1, i - 1)
            for i in range(1, 40)) + '<x v="${p39}"/>'
        self.assertError(r"the value would be longer than", body)

    def test_deep_nesting_is_an_error(self):
        self.assertError(r"elements nested more than \d+ deep", '<a>' * 1100 + '</a>' * 1100)


class CommandLineTest(XacroTestCase):

    def run_xacro(self, *args, stdin=None):
        return subprocess.run([sys.executable, SCRIPT] + list(args), input=stdin,
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              universal_newlines=True, timeout=60, cwd=self.tmp)

    def test_prints_the_urdf_and_takes_args_and_output_file(self):
        path = self.write('cli.urdf.xacro', robot(
            '<xacro:arg name="n" default="a"/><link name="$(arg n)"/>'))
        run = self.run_xacro(path)
        self.assertEqual(0, run.returncode, run.stderr)
        self.assertXml('<robot name="r"><link name="a"/></robot>', run.stdout)
        out = os.path.join(self.tmp, 'out.urdf')
        run = self.run_xacro(path, 'n:=b', '-o', out)
        self.assertEqual(0, run.returncode, run.stderr)
        self.assertEqual('', run.stdout)
        with open(out, encoding='utf-8') as stream:
            self.assertXml('<robot name="r"><link name="b"/></robot>', stream.read())
        run = self.run_xacro('-', 'n:=c', stdin=robot('<link name="$(arg n)"/>'))
        self.assertXml('<robot name="r"><link name="c"/></robot>', run.stdout)

    def test_an_error_goes_to_stderr_with_status_2(self):
        path = self.write('broken.urdf.xacro', robot('<link name="${nope}"/>'))
        run = self.run_xacro(path)
        self.assertEqual(2, run.returncode)
        self.assertEqual('', run.stdout)
        self.assertRegex(run.stderr, r"broken\.urdf\.xacro:3: \$\{nope\}: name 'nope' is not "
                                     r"defined")
        self.assertEqual(2, self.run_xacro().returncode)
        self.assertEqual(2, self.run_xacro(os.path.join(self.tmp, 'missing.xacro')).returncode)

    def test_reply_mode_for_the_node(self):
        path = self.write('reply.urdf.xacro', robot(
            '<xacro:arg name="n" default="a"/><link name="$(arg n)"/>'))
        run = self.run_xacro('--rbs-reply', str(1 << 30), float(10).hex(), path, 'n:=z')
        self.assertEqual(0, run.returncode, run.stderr)
        self.assertTrue(run.stdout.startswith('urdf\n'), run.stdout)
        self.assertXml('<robot name="r"><link name="z"/></robot>', run.stdout[5:])
        broken = self.write('reply_broken.xacro', robot('<link name="${nope}"/>'))
        run = self.run_xacro('--rbs-reply', str(1 << 30), float(10).hex(), broken)
        self.assertRegex(run.stdout, r"^error .*reply_broken\.xacro:3: \$\{nope\}: name 'nope' "
                                     r"is not defined\n$")


class RealShapedDescriptionTest(XacroTestCase):
    """test/data/xacro/packages/fake_arm_description: a two-link arm written
    the way the real descriptions are (turtlebot3, franka, universal_robot)."""

    ARM = os.path.join(PACKAGES, 'fake_arm_description', 'urdf', 'two_link_arm.urdf.xacro')

    def test_default_arguments_give_the_hand_expanded_urdf(self):
        with open(os.path.join(DATA, 'expected', 'two_link_arm.urdf'), encoding='utf-8') as stream:
            expected = stream.read()
        self.assertXml(expected, xacro.expand_file(self.ARM, {}))

    def test_other_arguments(self):
        root = ElementTree.fromstring(xacro.expand_file(
            self.ARM, {'prefix': 'r_', 'with_gripper': 'true', 'gazebo': 'false'}))
        self.assertEqual(['r_base_link', 'r_link1', 'r_link2', 'r_gripper'],
                         [link.get('name') for link in root.findall('link')])
        self.assertEqual(['r_shoulder', 'r_elbow', 'r_gripper_joint'],
                         [joint.get('name') for joint in root.findall('joint')])
        self.assertEqual([], root.findall('gazebo'))
        self.assertEqual(2, len(root.findall('transmission')))
        gripper = root.findall('link')[3]
        for part in ('visual', 'collision'):
            self.assertEqual('0.05 0.1 0.02', gripper.find(part + '/geometry/box').get('size'))
        ixx = float(gripper.find('inertial/inertia').get('ixx'))
        self.assertAlmostEqual(0.1 / 12 * (0.1 ** 2 + 0.02 ** 2), ixx, delta=1e-15)


if __name__ == '__main__':
    unittest.main(verbosity=2)
