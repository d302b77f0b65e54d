"""Test configuration: hypothesis profiles ("ci": 50 examples, "thorough": 1000); the default
evaluator compiles at first use (``PROJEQ_COMPILE=now``: the tests check the compiled kernels and
time them; tests/assembly/test_tiers.py checks the interpreted first tier of a new numba cache)."""

import os

os.environ.setdefault("PROJEQ_COMPILE", "now")

from hypothesis import HealthCheck, settings

settings.register_profile("ci", max_examples=50, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.register_profile("thorough", max_examples=1000, deadline=None, suppress_health_check=[HealthCheck.too_slow])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))
