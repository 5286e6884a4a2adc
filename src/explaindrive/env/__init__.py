"""The Gymnasium driving environment: observation, action, reward and metrics."""
