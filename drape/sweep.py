"""``python -m drape.sweep``: the ``drape sweep`` command (:func:`drape.cli.sweep.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.sweep loads no command line
    from drape.cli.sweep import main

    sys.exit(main())
