"""Fixture processes and launch files for the launcher tests (``tests/bringup/test_launch*.py``).

The tests put ``tests/bringup`` on PYTHONPATH, so ``Node(package='launch_fixtures',
executable='ticker')`` runs ``python -m launch_fixtures.ticker``.
"""
