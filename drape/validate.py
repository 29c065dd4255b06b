"""``python -m drape.validate``: the ``drape validate`` command (:func:`drape.cli.validate.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.validate loads no command line
    from drape.cli.validate import main

    sys.exit(main())
