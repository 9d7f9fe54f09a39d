"""``python -m gearbody.cli``: as the ``gearbody`` script."""

from gearbody.cli import run

run()
