"""`make demo`: placeholder until the reaching demo lands."""
print("demo: not yet available")
