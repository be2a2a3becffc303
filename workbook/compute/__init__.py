"""The compute stage: every requested value, table, chart series, check and Excel form, once."""
