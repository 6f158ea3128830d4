"""Servo facts below every other layer: models (datasheets) and tick arithmetic."""
