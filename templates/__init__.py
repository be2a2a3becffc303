"""Worksheet templates shipped with workbook (installed as package data)."""
