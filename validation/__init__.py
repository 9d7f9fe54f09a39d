"""Independent reference model for gearbody (shares no force-law or assembly code with gearbody)."""
