"""Evaluation of a loaded sheet: values, the numpy and SymPy back ends, ODEs, run-time arrays."""
