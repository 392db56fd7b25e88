"""percept: a camera-only driving stack on highway-env."""
