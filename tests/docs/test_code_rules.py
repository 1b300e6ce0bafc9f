"""Rules of the code that a grep can check (issue 29): no module reads or writes another class's
private attribute (``obj._name`` where ``_name`` is not defined in the same module), so a
change to a class's internals is an edit of its own module only."""

from __future__ import annotations

import re
from pathlib import Path

SRC = Path(__file__).resolve().parents[2] / 'src'

#: ``x._name`` / ``x.y._name`` / ``self.x._name``: a private attribute of some other object
_ACCESS = re.compile(r'(?<![\w.])([A-Za-z_]\w*(?:\.\w+)*)\.(_[a-z]\w*)\b')
#: what a module defines as its own: ``self._x =``, ``def _x``, a class-level ``_x =``
_OWN = (re.compile(r'self\.(_[a-z]\w*)\s*(?::[^=\n]*)?='), re.compile(r'def (_[a-z]\w*)'),
        re.compile(r'^\s+(_[a-z]\w*)\s*[:=]', re.M))
#: other libraries' private names we must use, each with the reason
ALLOWED = {
    'os._exit': 'exit right after the clean-up, as ROS 2 C++ nodes do (process.py)',
    'sys._current_frames': "the player's watchdog names where its thread is stuck",
    'value._fields': "a namedtuple's public field list (named with '_' by the stdlib)",
    'cond._ref': 'cyclonedds ReadCondition handle: attach with our own key (no public API)',
    'self._waitset._waitset_attach': 'cyclonedds WaitSet: attach with our own key',
    'self._waitset._ref': 'cyclonedds WaitSet handle for the attach above',
    'self._waitset._waitset_wait': 'cyclonedds WaitSet: wait that names what fired',
    'reader._constructor': 'cyclonedds builtin reader: endpoints without the type id',
    'self.reader._ref': 'cyclonedds reader handle for ddspy_take (zero-copy take)',
    'writer._ref': 'cyclonedds writer handle for ddspy_write',
}


def _foreign_private_accesses(path: Path, root: Path = SRC) -> list[str]:
    text = path.read_text(encoding='utf-8')
    own = {name for pattern in _OWN for name in pattern.findall(text)}
    found = []
    for n, line in enumerate(text.splitlines(), 1):
        code = line.split('#')[0]
        if re.match(r'\s*(from|import)\s', code) or code.lstrip().startswith(('"', "'", ':')):
            continue
        for match in _ACCESS.finditer(code):
            obj, attr = match.groups()
            if obj in ('self', 'cls') or attr in own or f'{obj}.{attr}' in ALLOWED:
                continue
            found.append(f'{path.relative_to(root)}:{n}: {obj}.{attr}')
    return found


def test_no_module_touches_another_classs_private_attributes():
    found = [hit for path in sorted(SRC.rglob('*.py')) for hit in _foreign_private_accesses(path)]
    assert not found, '\n'.join(found)


def test_the_check_finds_a_foreign_private_attribute(tmp_path):
    """The rule is not vacuous: what the lock-step runner once read is found."""
    sample = tmp_path / 'host.py'
    sample.write_text('def scan(timer, clock):\n    return timer._canceled or clock._override_ns\n'
                      'class Own:\n    def __init__(self):\n        self._x = 1\n'
                      '    def same(self, other):\n        return other._x\n')
    hits = [h.split(': ')[1] for h in _foreign_private_accesses(sample, tmp_path)]
    assert hits == ['timer._canceled', 'clock._override_ns']


# -- node identity ---------------------------------------------------------------------------
#: the name a node gives itself: ``super().__init__('name', ...)`` or ``NodeTraits(name=...)``
_NODE_NAME = re.compile(r"(?:super\(\)\.__init__\(|NodeTraits\((?:[^()]|\([^()]*\))*?\bname=)"
                        r"'([a-z][a-z0-9_]*)'")
#: node names that are documentation text, each with the reason
ALLOWED_NAMES = {
    ('mindgrasp_ros/mindgrasp_ros/topics.py', 'eeg_acquisition'):
        "the topic table's source column, prose for the README's table",
}


def _node_identities(root: Path = SRC) -> dict[str, str]:
    """Each node's identity as a string -> the package that owns it: its module
    (``mindgrasp_eeg.virtual_amp_node``) and its name when the name is a node's only meaning
    (``virtual_amp``; one-word names such as ``trainer`` or ``sim`` are also a robot, a
    paradigm or a package, which a grep cannot tell apart)."""
    out: dict[str, str] = {}
    for path in sorted(root.rglob('*_node.py')):
        package = path.relative_to(root).parts[0]
        match = _NODE_NAME.search(path.read_text(encoding='utf-8'))
        if match is None:
            continue
        out['.'.join(path.relative_to(root).parts[1:]).removesuffix('.py')] = package
        if '_' in match.group(1):
            out[match.group(1)] = package
    return out


def _foreign_node_identities(path: Path, identities: dict[str, str],
                             root: Path = SRC) -> list[str]:
    """String literals naming a node of another package (launch descriptions excepted: a
    ``Node(package=..., executable=..., name=...)`` action names its node, as in launch_ros)."""
    import ast

    rel = path.relative_to(root)
    if 'launch' in rel.parts[:-1]:      # launch files: the ROS convention
        return []
    tree = ast.parse(path.read_text(encoding='utf-8'))
    allowed: set[int] = set()
    for call in ast.walk(tree):
        if isinstance(call, ast.Call) and getattr(call.func, 'attr',
                                                  getattr(call.func, 'id', '')) == 'Node':
            allowed |= {id(k.value) for k in call.keywords}
    return sorted(f'{rel}:{node.lineno}: {node.value!r}' for node in ast.walk(tree)
                  if isinstance(node, ast.Constant) and isinstance(node.value, str)
                  and identities.get(node.value, rel.parts[0]) != rel.parts[0]
                  and id(node) not in allowed
                  and (rel.as_posix(), node.value) not in ALLOWED_NAMES)


def test_no_node_is_named_outside_its_package():
    """Which node prompts a phase, records the task, is the virtual subject: asked of the node
    classes (NodeTraits), so renaming a node is an edit of its own package and launch files."""
    identities = _node_identities()
    assert {'virtual_amp', 'trial_manager', 'mindgrasp_eeg.acquisition_node'} <= set(identities)
    found = [hit for path in sorted(SRC.rglob('*.py'))
             for hit in _foreign_node_identities(path, identities)]
    assert not found, '\n'.join(found)


def test_the_check_finds_a_node_named_elsewhere(tmp_path):
    """The rule is not vacuous: the session's former table of prompters is found; a launch
    action naming its node is not."""
    (tmp_path / 'pkg_a' / 'pkg_a').mkdir(parents=True)    # src/<package>/<package>/
    (tmp_path / 'pkg_b' / 'pkg_b').mkdir(parents=True)
    (tmp_path / 'pkg_a' / 'pkg_a' / 'graz_node.py').write_text(
        "class G:\n    node_traits = NodeTraits(prompts=('graz',),\n"
        "                             name='graz_prompter')\n")
    sample = tmp_path / 'pkg_b' / 'pkg_b' / 'session.py'
    sample.write_text("PROMPTERS = {'graz': 'graz_prompter'}\n"
                      "n = Node(package='pkg_a', executable='graz_node', name='graz_prompter')\n"
                      "m = 'pkg_a.graz_node'\n")
    identities = _node_identities(tmp_path)
    assert identities == {'pkg_a.graz_node': 'pkg_a', 'graz_prompter': 'pkg_a'}
    hits = [h.split(': ')[1] for h in _foreign_node_identities(sample, identities, tmp_path)]
    assert hits == ["'graz_prompter'", "'pkg_a.graz_node'"]
