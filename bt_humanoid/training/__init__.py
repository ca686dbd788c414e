"""Training the learned parts from views rendered in the simulator (ground truth labels, training only)."""
