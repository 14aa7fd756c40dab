"""The mpc compiler: definition files → IR programs → model files."""
