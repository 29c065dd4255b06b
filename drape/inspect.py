"""``python -m drape.inspect``: the ``drape inspect`` command (:func:`drape.cli.inspect.main`)."""
import sys

if __name__ == "__main__":
    # under the guard: importing drape.inspect loads no command line
    from drape.cli.inspect import main

    sys.exit(main())
