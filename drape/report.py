"""``python -m drape.report``: the ``drape report`` command (:func:`drape.batch.report.main`)."""
import sys

if __name__ == "__main__":
    from drape.batch.report import main

    sys.exit(main())
