"""pint definition files shipped with workbook (installed as package data)."""
