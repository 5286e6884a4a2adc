"""The passenger web interface: watch the ride, talk to the car, read its explanations."""

from explaindrive.web.app import RealStack, create_app

__all__ = ["RealStack", "create_app"]
