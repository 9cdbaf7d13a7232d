"""Testing utilities shipped with csplab: hypothesis strategies and brute-force references."""
