"""``python -m mindgrasp_cli`` is the ``mindgrasp`` command."""

import sys

from mindgrasp_cli.cli import main

sys.exit(main())
