"""Continuous model synthesis (thesis Ch. 4)."""
