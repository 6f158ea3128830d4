"""ROBOTIS Dynamixel buses on ``dynamixel_sdk``: Protocol 2.0 (``protocol2``: X, MX 2.0,
XL-320) and Protocol 1.0 (``protocol1``: AX, MX 1.0), which shares 2.0's port."""
