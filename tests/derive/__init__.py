"""Tests of `stringstab.derive`: the SymPy derivations, the errata, the generated code.

One folder of the table in docs/architecture.md, "The tests".
"""
