"""Design of experiments for process settings (METHODS section 2)."""
