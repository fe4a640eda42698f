"""Command-line programs of halsdk (halsampler, halstreamer, ...)."""
