"""The bundled cases: example case files, the material library, the validation set.

This folder is the only copy of these files. Installed from a wheel it is the package
``fabric_drape_cases`` (see :mod:`constitutive.bundled`); in a source tree it is read in place.
"""
