"""``python -m gearbody.cli``: as the ``gearbody`` script."""

import sys

from gearbody.cli import main

sys.exit(main())
