"""``python -m alight``: the same as the ``alight`` command."""

import sys

from alight.frontends.cli import main

sys.exit(main())
