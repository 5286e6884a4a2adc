"""The passenger ride: commands in, D3QN driving, explanations out, in a closed loop."""
