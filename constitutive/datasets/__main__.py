"""``python -m constitutive.datasets``: the ``drape datasets`` command (:func:`drape.cli.datasets.main`)."""
import sys

from drape.cli.datasets import main

sys.exit(main())
