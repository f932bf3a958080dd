// Replaced by the servo law (issue #7).
