"""Finite-element plate and shell models of fabric, time integration and the case runner.

The FE layer knows the constitutive law only through its state-object interface
(``trial`` / ``commit``) from :mod:`constitutive`.
"""
