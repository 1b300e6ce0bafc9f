"""Trials as Ray tasks on a local Ray instance (2 CPUs on this machine): the same records as
one worker."""

from __future__ import annotations

from pathlib import Path

import pytest

from .test_experiment_cli import last_json, mindgrasp


@pytest.mark.slow
@pytest.mark.timeout(1800)   # Ray's start-up and whole experiments, on a loaded machine
def test_ray_gives_the_records_of_one_worker(tmp_path: Path) -> None:
    csv = []
    for how in (['--workers', '1'], ['--ray', 'auto']):
        out = tmp_path / how[0].strip('-')
        s = last_json(mindgrasp('experiment', 'set-locations', '--trials', '2', '--subject',
                                'virtual', '--accuracy', '0.8', '--seed', '7', *how,
                                '--trial-timeout', '4', '--out', str(out), '--json',
                                '--no-progress'))
        assert s['trials'] == 2          # two Ray tasks at once on the 2 CPUs
        csv.append((out / 'records.csv').read_text())
    assert csv[0] == csv[1]


def test_an_unreachable_ray_address_is_one_line() -> None:
    result = mindgrasp('experiment', 'set-locations', '--ray', '127.0.0.1:9', timeout=120)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and 'the Ray cluster cannot be reached' in lines[0], result.stderr
    result = mindgrasp('experiment', 'sweep', '--ray', 'nohost', timeout=120)
    assert result.returncode == 2 and 'is not a Ray address' in result.stderr, result.stderr
