"""The drivers that ship with halsdk (``loadrt NAME`` finds them here)."""
