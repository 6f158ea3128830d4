"""MuJoCo side of biped: MJCF generation, the simulated bus, and the pty servo emulator."""
