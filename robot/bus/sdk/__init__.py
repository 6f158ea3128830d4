"""What the vendor-SDK buses (Dynamixel, Feetech) share: the bus on an SDK (``bus``),
register access (``registers``), the port pieces (``port``), the stale-free sync read
(``sync_read``), the servos' own watchdog (``failsafe``) and the gains written before
torque on (``gain_writer``)."""
