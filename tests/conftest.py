"""Under CI, property tests draw the same examples on every run: a red CI is a bug in
the change, never a new random draw (run them locally to explore new examples)."""

import os

from hypothesis import settings

settings.register_profile("ci", derandomize=True)
if os.environ.get("CI"):
    settings.load_profile("ci")
