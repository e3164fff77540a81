"""Linear analysis of a generated model: equilibria and linearization (linearize), and the
Jacobians of one step of a method (step_derivatives). Builds on run/ and the steppers."""
