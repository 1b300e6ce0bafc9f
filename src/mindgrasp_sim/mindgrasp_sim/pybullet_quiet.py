"""``pybullet`` (and its ``BulletClient``) imported without its banner.

The C module prints ``pybullet build time: ...`` to stderr when it is imported: a line in every
command that loads the simulator's node class (the experiment commands do so to read its traits
before the first trial), printed before the one-line error a bad argument gets. Import ``pb`` from
here instead of ``import pybullet``.
"""

from __future__ import annotations

import os
import sys

if 'pybullet' not in sys.modules:
    sys.stderr.flush()
    _saved = os.dup(2)
    _null = os.open(os.devnull, os.O_WRONLY)
    try:
        os.dup2(_null, 2)
        import pybullet  # noqa: F401  (an ImportError is raised, not printed: nothing is hidden)
    finally:
        os.dup2(_saved, 2)
        os.close(_saved)
        os.close(_null)

import pybullet as pb
from pybullet_utils.bullet_client import BulletClient

__all__ = ['BulletClient', 'pb']
