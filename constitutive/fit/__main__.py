"""``python -m constitutive.fit``: :func:`constitutive.fit.cli.main`."""
import sys

from constitutive.fit.cli import main

sys.exit(main())
