"""The second solver: every query whose answer discharges something is
decided again by cvc5 from its SMT-LIB2 text, its proof produced and
checked (docs/second-solver.md)."""
