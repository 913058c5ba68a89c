"""Tests of `stringstab demo` (`cli.demo_steps`): each step and the outputs.

One folder of the table in docs/architecture.md, "The tests".
"""
