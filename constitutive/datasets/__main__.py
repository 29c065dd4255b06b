"""``python -m constitutive.datasets``: :func:`constitutive.datasets.cli.main`."""
import sys

from constitutive.datasets.cli import main

sys.exit(main())
