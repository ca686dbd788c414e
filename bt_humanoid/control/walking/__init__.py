"""The biped's balance and walking controller (docs/walking.md): state estimation, balance, and the layers above."""
