"""``python -m mindgrasp_bringup`` is the ``mindgrasp`` command."""

import sys

from mindgrasp_bringup.cli import main

sys.exit(main())
