"""`python -m laserpick.cli`: the `laserpick` script."""

import sys

from laserpick.cli import main

sys.exit(main())
