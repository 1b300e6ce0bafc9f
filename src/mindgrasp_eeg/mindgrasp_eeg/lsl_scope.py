"""Keep LSL on this host unless the user widens it (liblsl's configuration file).

liblsl reads its settings once, when the first stream is made or resolved, from the file named by
``LSLAPICFG`` (or ``lsl_api.cfg`` in the working or home directory). Unless the user says
otherwise, :func:`apply_lsl_scope` points ``LSLAPICFG`` at a file with::

    [ports]
    IPv6 = disable
    [multicast]
    ResolveScope = machine
    ListenAddress = 127.0.0.1

so stream discovery (queries and answers, UDP 16571) stays on the loopback interface: no other
machine can find our streams, and the acquisition node finds only streams of this machine.
liblsl 1.18 (bundled by pylsl) has no setting for the address of an outlet's own sockets (its
time service, UDP, and data server, TCP, still bind 0.0.0.0 on the first free ports from 16572
on); a firewall closes those when that matters.

Widening is one setting: ``MINDGRASP_LSL_SCOPE=network`` (e.g. the amplifier's LSL app runs on
another computer). A user's own ``LSLAPICFG`` is always kept as it is.
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from mindgrasp_eeg.errors import EEGError

#: environment variable choosing the scope: ``machine`` (default) or ``network``
SCOPE_ENV = 'MINDGRASP_LSL_SCOPE'
SCOPES = ('machine', 'network')

MACHINE_CONFIG = """\
; written by mindgrasp_eeg.lsl_scope: LSL stream discovery on this machine only
; (MINDGRASP_LSL_SCOPE=network, or your own LSLAPICFG, widens it)
[ports]
IPv6 = disable
[multicast]
ResolveScope = machine
ListenAddress = 127.0.0.1
"""


def apply_lsl_scope(environ: dict[str, str] | None = None, scope: str | None = None
                    ) -> Path | None:
    """Set ``LSLAPICFG`` for the scope (default: ``$MINDGRASP_LSL_SCOPE``, else machine), before
    liblsl reads its configuration.

    Returns the configuration file written, or None when liblsl's own defaults (network) or the
    user's ``LSLAPICFG`` apply. ``environ`` defaults to ``os.environ``.
    """
    env = os.environ if environ is None else environ
    if env.get('LSLAPICFG'):
        return None
    text = env.get(SCOPE_ENV, '') if scope is None else scope
    scope = text.strip().lower() or 'machine'
    if scope not in SCOPES:
        msg = (f'{SCOPE_ENV}={text!r} is not a scope; use machine (LSL streams on this host '
               f'only, the default) or network.')
        raise EEGError(msg)
    if scope == 'network':
        return None
    path = Path(tempfile.gettempdir()) / f'mindgrasp-lsl-machine-{os.getuid()}.cfg'
    if not path.is_file() or path.read_text(encoding='utf-8') != MACHINE_CONFIG:
        tmp = path.with_name(f'{path.name}.{os.getpid()}')
        tmp.write_text(MACHINE_CONFIG, encoding='utf-8')
        tmp.replace(path)                 # atomic: a parallel process never reads half a file
    env['LSLAPICFG'] = str(path)
    return path
