"""What the README states about the libraries and the recorder is what they do."""

from __future__ import annotations

import re
from pathlib import Path

import pylsl

from mindgrasp_launch.run_extras import COMMON_ARGUMENTS

README = (Path(__file__).resolve().parents[2] / 'README.md').read_text(encoding='utf-8')


def test_the_liblsl_version_the_readme_names_is_the_bundled_one() -> None:
    named = set(re.findall(r'liblsl (\d+\.\d+)', README))
    version = pylsl.library_version()          # e.g. 118 for 1.18
    assert named == {f'{version // 100}.{version % 100}'}, named


def test_every_common_launch_argument_is_in_the_readme() -> None:
    for argument in COMMON_ARGUMENTS:
        assert f'`{argument.name}:=' in README, argument.name
