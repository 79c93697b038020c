"""`python -m tvoronoi`: the same as the `tvoronoi` command."""

import sys

from tvoronoi.cli import main

sys.exit(main())
