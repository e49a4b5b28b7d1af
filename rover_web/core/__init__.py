"""What every feature shares: the per-app state (Rover), background loops and leases."""
