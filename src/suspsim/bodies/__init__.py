"""Rigid bodies: shapes and packings."""
