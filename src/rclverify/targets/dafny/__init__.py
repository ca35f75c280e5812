"""Dafny text of RCL formulas, types and literals (the Dafny backend's translation)."""
