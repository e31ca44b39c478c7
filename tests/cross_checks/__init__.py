"""Cross-checks of gmuk against independent implementations (Pinocchio)."""
