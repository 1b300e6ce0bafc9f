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
