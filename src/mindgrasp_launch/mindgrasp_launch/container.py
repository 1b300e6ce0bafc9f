"""The process of ``mindgrasp launch --composed``: loads node modules as components and spins
them under one executor until SIGINT.

    python -m mindgrasp_launch.container <run dir>/composed.yaml
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

import yaml


def main(argv: Sequence[str] | None = None) -> int:
    """Run the components listed in the file given as the only argument."""
    argv = list(sys.argv[1:] if argv is None else argv)
    if len(argv) != 1:
        print('usage: python -m mindgrasp_launch.container <composed.yaml>',
              file=sys.stderr)
        return 2
    with open(argv[0], encoding='utf-8') as f:
        plan = yaml.safe_load(f)
    from mindgrasp_ros.graph import CompositionError, NodeSpec, run_composed

    components = [NodeSpec(c['label'], c['module'], ros_args=list(c['ros_args']))
                  for c in plan['components']]
    print(f'container: composing {len(components)} node(s): '
          + ', '.join(f"{c['label']} ({c['module']})" for c in plan['components']), flush=True)
    try:
        return run_composed(components)
    except CompositionError as exc:
        print(f'container: {exc}', file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return 0


if __name__ == '__main__':
    sys.exit(main())
