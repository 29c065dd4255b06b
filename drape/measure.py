"""``python -m drape.measure``: the ``drape measure`` command (:func:`drape.analyses.scan_measure.main`)."""
import sys

if __name__ == "__main__":
    from drape.analyses.scan_measure import main

    sys.exit(main())
