"""``python -m relrl`` is the ``relrl`` command."""

import sys

from relrl.cli import main

sys.exit(main())
