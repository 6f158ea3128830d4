"""Feetech STS/SMS and SCS buses on ``scservo_sdk`` (``bus``)."""
