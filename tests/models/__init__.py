"""Tests of optdesign.models: the motor in the drive and its catalogue (issue 37)."""
