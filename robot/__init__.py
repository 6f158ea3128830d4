"""biped: a trigonometric-gait puppeteering driver for hobby servo bipeds."""

__version__ = "0.1.0"
