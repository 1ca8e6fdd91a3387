"""Mission files: schema (:mod:`.spec`) and loading with cross-checks (:mod:`.loader`)."""
