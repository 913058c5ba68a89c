"""Tests of the root modules: `parallel` (start methods, no fork with a thread), `progress`, the
plain numbers of `errors`.

One folder of the table in docs/architecture.md, "The tests".
"""
