# SPDX-License-Identifier: GPL-2.0-or-later
"""stickslip: the stick-slip friction law of Khellaf & Mansouri (2024) on five engines."""
__version__ = "1.0.0"  # pyproject.toml's version (tests/test_release.py checks they agree)
