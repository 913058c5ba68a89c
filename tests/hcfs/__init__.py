"""Tests of `stringstab.hcfs`: the HCFS model, switch, jerk theorem, DDPG and leaders.

One folder of the table in docs/architecture.md, "The tests".
"""
