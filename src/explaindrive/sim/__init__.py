"""SUMO side: locating SUMO, the urban scenario, demand, and the simulation connection."""
