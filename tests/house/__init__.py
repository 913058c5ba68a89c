"""Tests of the house rules: layers and imports, docstrings, the README's and CI's command, project
habits, this layout.

One folder of the table in docs/architecture.md, "The tests".
"""
