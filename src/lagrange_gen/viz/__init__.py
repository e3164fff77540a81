"""Pictures of a Trajectory: plots (plot) and animations of a model's Drawing (animate).
matplotlib is imported here and nowhere in the runtime."""
