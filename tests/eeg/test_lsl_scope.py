"""LSL stays on this host by default: the virtual amplifier's discovery sockets bind loopback."""

from __future__ import annotations

import subprocess
import sys
import time

import psutil
import pytest

from mindgrasp_eeg import EEGError
from mindgrasp_eeg.lsl_scope import MACHINE_CONFIG, SCOPE_ENV, apply_lsl_scope

#: liblsl's discovery port (multicast and unicast queries)
DISCOVERY_PORT = 16571


def test_machine_scope_is_the_default_and_the_users_config_is_kept(tmp_path) -> None:
    env: dict[str, str] = {}
    path = apply_lsl_scope(env)
    assert path is not None and env['LSLAPICFG'] == str(path)
    assert path.read_text(encoding='utf-8') == MACHINE_CONFIG
    assert apply_lsl_scope({SCOPE_ENV: 'network'}) is None
    own = {'LSLAPICFG': str(tmp_path / 'mine.cfg')}
    assert apply_lsl_scope(own) is None and own['LSLAPICFG'] == str(tmp_path / 'mine.cfg')
    with pytest.raises(EEGError, match=r"MINDGRASP_LSL_SCOPE='everywhere' is not a scope; use "
                                       r'machine .* or network'):
        apply_lsl_scope({SCOPE_ENV: 'everywhere'})


def _sockets(pid: int) -> list[tuple[str, str, int]]:
    return [(c.type.name, c.laddr.ip, c.laddr.port)
            for c in psutil.Process(pid).net_connections(kind='inet') if c.laddr]


@pytest.mark.slow
def test_virtual_amp_discovery_binds_loopback_only(spawn_node, stream_name) -> None:
    """The node's process: LSL's discovery listener on 127.0.0.1, no IPv6 socket of LSL; the
    stream is still found from this machine. (DDS and LSL's data port bind 0.0.0.0: see the
    README's network section.)"""
    amp = spawn_node('mindgrasp_eeg.virtual_amp_node', stream_name=stream_name,
                     env={'LSLAPICFG': '', SCOPE_ENV: ''})
    deadline = time.monotonic() + 60
    while time.monotonic() < deadline and not any(
            p == DISCOVERY_PORT for _, _, p in _sockets(amp.pid)):
        assert amp.poll() is None, amp.output()
        time.sleep(0.2)
    discovery = [(t, ip) for t, ip, p in _sockets(amp.pid) if p == DISCOVERY_PORT]
    assert discovery and all(ip == '127.0.0.1' for _, ip in discovery), _sockets(amp.pid)
    assert not [s for s in _sockets(amp.pid) if ':' in s[1] and s[2] >= DISCOVERY_PORT], \
        _sockets(amp.pid)
    # a resolver on this machine (another process, liblsl defaults) still finds the stream
    found = subprocess.run(
        [sys.executable, '-c', 'import sys, pylsl; print(len(pylsl.resolve_byprop("name", '
                               'sys.argv[1], timeout=30)))', stream_name],
        capture_output=True, text=True, timeout=120, env={'PATH': '/usr/bin:/bin'})
    assert found.stdout.strip() == '1', found.stderr[-2000:]
    assert amp.stop() == 0
