"""The worksheet language: text read into a spec, expressions parsed, units and shapes typed."""
