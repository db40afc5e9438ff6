"""stickslip: the stick-slip friction law of Khellaf & Mansouri (2024) on three engines."""
__version__ = "0.1.0"
