"""Sensors: each turns a plant's Scene into a measurement (cameras render images and measure them)."""
