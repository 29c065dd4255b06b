"""``python -m drape.measure``: the ``drape measure`` command (:func:`drape.cli.measure.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.measure loads no command line
    from drape.cli.measure import main

    sys.exit(main())
