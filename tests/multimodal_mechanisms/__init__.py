"""Test plug-ins with multimodal design landscapes, each with an independent reference."""
