"""Reports a lab can keep: their content (`document`) and their pictures (`figures`)."""
