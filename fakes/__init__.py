"""stairbot.fakes: the simulated robot (pymunk world, sensor and motor models)."""
