"""The built-in functions and constants: one registry entry each, and what they compute."""
