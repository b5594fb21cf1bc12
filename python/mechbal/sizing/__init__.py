"""Offline sizing of balancing elements: one module per method, each citing its paper."""
