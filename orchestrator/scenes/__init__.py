"""Scene families: what a mechanism's runs report (analysis) and its yardstick (reference)."""
