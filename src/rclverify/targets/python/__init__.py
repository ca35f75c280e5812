"""The evaluator and contract data that generated Python packages carry."""
