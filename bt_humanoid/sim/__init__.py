"""MuJoCo world assembly, stepping, cameras and ground truth."""
