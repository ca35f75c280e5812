"""RCL formulas in canonical forms for AJPF's property mapping table (matching and instantiation stay in the model-checking backend)."""
