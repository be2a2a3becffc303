"""The renderers: functions of a computed sheet that write files (xlsx, report, notebook)."""
