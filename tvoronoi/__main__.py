"""``python -m tvoronoi``: the console script."""

import sys

from tvoronoi.cli import main

sys.exit(main())
