"""``python -m drape.report``: the ``drape report`` command (:func:`drape.cli.report.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.report loads no command line
    from drape.cli.report import main

    sys.exit(main())
