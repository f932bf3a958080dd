// Replaced by recognition (issue #6).
