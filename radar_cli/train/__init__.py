"""Training RADAR: the step (render + losses), data, checkpoints, logging, distributed set-up and the loop."""
