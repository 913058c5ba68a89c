"""The tests of stringstab, one folder a capability (docs/architecture.md, "The tests")."""
