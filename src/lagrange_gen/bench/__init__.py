"""`lagrange-gen bench`: measurements that belong in reports, never in test assertions."""
