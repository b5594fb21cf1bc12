"""Offline sizing of balancing elements, one module per method (each cites its paper)."""
