#!/usr/bin/env python3
"""Checks the README's ROS API tables against what the running node declares.

The README is the node's reference: a service, topic or parameter added to the
node but not to the README, or left in the README after it was removed, or a
default that drifted from the code, is a bug that no other test sees. Run by
readme_api_test.test; `readme_api_test.py --self-check` runs only the check of
the table parser, which needs no ROS master.
"""

import math
import re
import sys
import time
import unittest

import rosgraph.masterapi
import rospkg
import rospy

PKG = 'rigid_body_sim'
NODE = '/rigid_body_sim'
API_HEADINGS = ('Services', 'Topics', 'Parameters')
# roscpp gives every node these two services; the README does not list them.
STANDARD_SERVICES = {NODE + '/get_loggers', NODE + '/set_logger_level'}
# s to wait for the node's registrations to settle: it writes its parameters
# back and registers its publishers and services one after the other, so a
# first look may catch it half way.
SETTLE_TIMEOUT = 10.0

_SEPARATOR_CELL = re.compile(r'^:?-+:?$')
_CODE = re.compile(r'`([^`]+)`')


def _split_row(line):
    """The cells of a markdown table row, stripped; `\\|` is a literal bar."""
    line = line.strip().replace('\\|', '\0')
    if line.startswith('|'):
        line = line[1:]
    if line.endswith('|'):
        line = line[:-1]
    return [cell.strip().replace('\0', '|') for cell in line.split('|')]


def parse_api_tables(markdown, headings=API_HEADINGS):
    """Reads the first table under each `### <heading>` of `markdown`.

    Returns {heading: (header, rows)}, header being the lower-cased header
    cells and each row a dict with 'names' (the backticked names of its first
    cell that start with '~' or '/'), 'cells' (all its cells) and 'line' (the
    row as written, for messages). Headings not found are left out. Headings
    inside fenced code blocks do not count.
    """
    tables = {}
    section = None  # heading whose table is being looked for, or None
    lines = []  # that table's lines so far
    in_fence = False

    def finish():
        if section is not None and lines:
            tables[section] = _parse_table(lines)

    for raw in markdown.splitlines():
        stripped = raw.strip()
        if stripped.startswith('```') or stripped.startswith('~~~'):
            in_fence = not in_fence
            continue
        if in_fence:
            continue
        heading = re.match(r'^(#{1,6})\s+(.*?)\s*#*\s*$', stripped)
        if heading:
            finish()
            title = heading.group(2)
            section = (title if len(heading.group(1)) == 3 and title in headings and
                       title not in tables else None)
            lines = []
            continue
        if section is None:
            continue
        if stripped.startswith('|'):
            lines.append(stripped)
        elif lines:
            # The table ended; only the first one under the heading counts.
            finish()
            section = None
            lines = []
    finish()
    return tables


def _parse_table(lines):
    header = [cell.lower() for cell in _split_row(lines[0])]
    body = lines[1:]
    if body and all(_SEPARATOR_CELL.match(cell) for cell in _split_row(body[0])):
        body = body[1:]
    rows = []
    for line in body:
        cells = _split_row(line)
        names = [name.strip() for name in _CODE.findall(cells[0])]
        rows.append({
            'names': [name for name in names if name.startswith(('~', '/'))],
            'cells': cells,
            'line': line,
        })
    return header, rows


def parse_number(text):
    """The number a README cell starts with ('1/240 s', '1e-6 m/s', '20'), or None.

    A cell starting with a bracketed list ('(0, 0, −9.81) m/s²') gives a list
    of numbers. Anything else ('true', 'world', '—') gives None.
    """
    text = text.replace('`', '').replace('\u2212', '-').replace('\u00a0', ' ').strip()
    if not text:
        return None
    listed = re.match(r'^[\(\[]([^\)\]]*)[\)\]]', text)
    if listed:
        values = [_parse_scalar(item) for item in listed.group(1).split(',')]
        return values if values and None not in values else None
    return _parse_scalar(text.split()[0].rstrip(',;'))


def _parse_scalar(token):
    token = re.sub(r'(?<=\d),(?=\d{3}(\D|$))', '', token.strip())  # 1,000
    fraction = re.fullmatch(r'([-+]?[0-9.]+(?:[eE][-+]?\d+)?)/([-+]?[0-9.]+(?:[eE][-+]?\d+)?)',
                            token)
    try:
        if fraction:
            value = float(fraction.group(1)) / float(fraction.group(2))
        else:
            value = float(token)
    except (ValueError, ZeroDivisionError):
        return None
    return value if math.isfinite(value) else None


def resolve(name):
    """'~spawn' -> '/rigid_body_sim/spawn'; global names stay as they are."""
    return NODE + '/' + name[1:] if name.startswith('~') else name


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def _eventually(compute, holds, timeout=SETTLE_TIMEOUT):
    """compute() until holds(result) or `timeout` s have passed; the last result."""
    deadline = time.monotonic() + timeout
    result = compute()
    while not holds(result) and time.monotonic() < deadline:
        time.sleep(0.2)
        result = compute()
    return result


class ReadmeApiTest(unittest.TestCase):

    def _tables(self):
        path = rospkg.RosPack().get_path(PKG) + '/README.md'
        with open(path, encoding='utf-8') as readme:
            tables = parse_api_tables(readme.read())
        for heading in API_HEADINGS:
            self.assertIn(heading, tables, '%s has no table under "### %s"' % (path, heading))
            header, rows = tables[heading]
            self.assertTrue(rows, 'the "### %s" table of %s is empty' % (heading, path))
            for row in rows:
                self.assertTrue(row['names'],
                                'no `~name` or `/name` in the first cell of this row of the '
                                '"### %s" table: %s' % (heading, row['line']))
        return tables

    def _system_state(self):
        rospy.wait_for_service(NODE + '/spawn', timeout=30)
        return rosgraph.masterapi.Master(rospy.get_name()).getSystemState()

    def test_services_match_the_readme(self):
        _, rows = self._tables()['Services']
        documented = {resolve(name) for row in rows for name in row['names']}

        def provided():
            _, _, services = self._system_state()
            return {name for name, providers in services
                    if NODE in providers and name not in STANDARD_SERVICES}

        actual = _eventually(provided, lambda names: names == documented)
        self.assertEqual(
            set(), actual - documented,
            'services the node provides that the README\'s "### Services" table lacks')
        self.assertEqual(
            set(), documented - actual,
            'services in the README\'s "### Services" table that the node does not provide')

    def test_topics_match_the_readme(self):
        _, rows = self._tables()['Topics']
        documented = {resolve(name) for row in rows for name in row['names']}
        # Per-model topics ('~<model>/joint_states') exist once such a model
        # is spawned; their rows are patterns that the topics must match.
        templates = {name for name in documented if '<model>' in name}
        documented -= templates
        patterns = [re.compile('^' + re.escape(name).replace(re.escape('<model>'), '[^/]+') + '$')
                    for name in templates]
        # The node advertises /clock only when it drives sim time.
        optional = set() if rospy.get_param('/use_sim_time', False) else {'/clock'}

        def published():
            publishers, _, _ = self._system_state()
            return {topic for topic, nodes in publishers
                    if NODE in nodes and topic != '/rosout' and
                    not any(pattern.match(topic) for pattern in patterns)}

        actual = _eventually(published, lambda topics: topics == documented - optional or
                             topics == documented)
        self.assertEqual(
            set(), actual - documented,
            'topics the node publishes that the README\'s "### Topics" table lacks')
        self.assertEqual(
            set(), documented - optional - actual,
            'topics in the README\'s "### Topics" table that the node does not publish')

    def test_parameters_and_defaults_match_the_readme(self):
        header, rows = self._tables()['Parameters']
        default_columns = [i for i, title in enumerate(header) if 'default' in title]
        self.assertTrue(default_columns,
                        'the "### Parameters" table has no default column: %s' % header)
        default_column = default_columns[0]
        documented = {}  # leaf name without '~' -> its default cell
        for row in rows:
            for name in row['names']:
                if name.startswith('~') and name != '~models':
                    cells = row['cells']
                    documented[name[1:]] = (cells[default_column]
                                            if default_column < len(cells) else '')
        prefix = NODE + '/'
        rospy.wait_for_service(NODE + '/spawn', timeout=30)

        def on_server():
            names = set()
            for name in rospy.get_param_names():
                if not name.startswith(prefix):
                    continue
                leaf = name[len(prefix):]
                if leaf == 'models' or leaf.startswith('models/'):
                    continue
                names.add(leaf)
            return names

        actual = _eventually(on_server, lambda names: names == set(documented))
        # Every difference at once, so that one run lists all the README needs.
        problems = ['~%s: on the parameter server under %s, not in the README\'s "### Parameters" '
                    'table' % (leaf, prefix) for leaf in sorted(actual - set(documented))]
        problems += ['~%s: in the README\'s "### Parameters" table, not on the parameter server '
                     'under %s' % (leaf, prefix) for leaf in sorted(set(documented) - actual)]
        compared = 0
        for leaf in sorted(set(documented) & actual):
            expected = parse_number(documented[leaf])
            if expected is None:
                continue
            value = rospy.get_param(prefix + leaf)
            if isinstance(expected, list):
                matches = (isinstance(value, list) and len(value) == len(expected) and
                           all(_is_number(v) and math.isclose(v, e, rel_tol=1e-9)
                               for v, e in zip(value, expected)))
            else:
                matches = _is_number(value) and math.isclose(value, expected, rel_tol=1e-9)
            compared += 1
            if not matches:
                problems.append('~%s: README default %r (%s), parameter server %r' %
                                (leaf, documented[leaf], expected, value))
        self.assertEqual([], problems, 'the README\'s parameters differ from the node\'s')
        # Most parameters are numbers; comparing only a handful would mean
        # the default column was misread.
        self.assertGreaterEqual(compared, 10,
                                'only %d numeric defaults were read from the README' % compared)

    def test_readme_parser_reads_a_sample(self):
        sample = '\n'.join([
            '# title',
            '```sh',
            '### Services',
            '```',
            '### Services',
            '',
            'Private services:',
            '',
            '| name | type | what |',
            '|---|:---:|---|',
            '| `~spawn` | `rigid_body_sim/Spawn` | adds a model |',
            '| `~set_paused`, `~step` | `std_srvs/SetBool` | a \\| bar |',
            '',
            '| `~not_this_table` | x |',
            '',
            '### Topics',
            '| topic | type |',
            '|---|---|',
            '| `/tf` | `tf2_msgs/TFMessage` |',
            '| `~states` | `rigid_body_sim/ModelStates` |',
            '## Elsewhere',
            '| `~not_a_topic` | x |',
            '### Parameters',
            '| parameter | Default | meaning |',
            '|---|---|---|',
            '| `~time_step` | `1/240` s | step |',
            '| `~solver/velocity_tolerance` | 1e-6 m/s | tolerance |',
            '| `~gravity` | (0, 0, \u22129.81) m/s\u00b2 | gravity |',
            '| `~world_frame` | `world` | frame |',
            '| `~max_hull_vertices` | 1,000 | vertices |',
        ])
        tables = parse_api_tables(sample)
        self.assertEqual(set(API_HEADINGS), set(tables))
        header, rows = tables['Services']
        self.assertEqual(['name', 'type', 'what'], header)
        self.assertEqual([['~spawn'], ['~set_paused', '~step']], [row['names'] for row in rows])
        self.assertEqual('a | bar', rows[1]['cells'][2])
        _, rows = tables['Topics']
        self.assertEqual(['/rigid_body_sim/states', '/tf'],
                         sorted(resolve(row['names'][0]) for row in rows))
        header, rows = tables['Parameters']
        self.assertEqual(1, [i for i, title in enumerate(header) if 'default' in title][0])
        defaults = {row['names'][0]: parse_number(row['cells'][1]) for row in rows}
        self.assertEqual(1.0 / 240.0, defaults['~time_step'])
        self.assertEqual(1e-6, defaults['~solver/velocity_tolerance'])
        self.assertEqual([0.0, 0.0, -9.81], defaults['~gravity'])
        self.assertIsNone(defaults['~world_frame'])
        self.assertEqual(1000.0, defaults['~max_hull_vertices'])
        self.assertIsNone(parse_number('true'))
        self.assertIsNone(parse_number('nan'))
        self.assertIsNone(parse_number('1/0'))
        self.assertEqual(20.0, parse_number('20'))


if __name__ == '__main__':
    if '--self-check' in sys.argv:
        unittest.main(argv=[sys.argv[0], 'ReadmeApiTest.test_readme_parser_reads_a_sample'])
    else:
        import rostest
        rospy.init_node('readme_api_test', anonymous=True)
        rostest.rosrun(PKG, 'readme_api', ReadmeApiTest)
