"""A simulated Mesa HostMot2 Ethernet card (LBP16 over UDP): ``hm2-sim``."""

from .card import Card
from .lbp16 import Command, Lbp16Error
from .profiles import PROFILES, Profile, profile
from .server import Faults, Hm2Sim, SimError, Stats

__all__ = ["Card", "Command", "Lbp16Error", "PROFILES", "Profile", "profile",
           "Faults", "Hm2Sim", "SimError", "Stats"]
