"""LittleDog quadruped: model, kinematics, gaits, sensing, simulation, trial logs, power (lesson 04)."""
from .power import battery_energy, cost_of_transport, endurance, trial_power

__all__ = ["battery_energy", "cost_of_transport", "endurance", "trial_power"]
