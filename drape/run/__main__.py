"""``python -m drape.run CASE``: :func:`drape.run.runner.main`."""
import sys

from drape.run.runner import main

sys.exit(main())
