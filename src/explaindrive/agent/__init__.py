"""D3QN driving agents: network, replay, learner, training loop and the merged controller."""
