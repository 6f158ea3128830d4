"""Servo buses: one interface (base.Bus), vendor backends, and a factory."""
