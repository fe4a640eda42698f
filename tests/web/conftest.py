"""The web tests' fixtures: ``browser`` (chromium under Playwright, one
per module) from :mod:`helpers.web`."""

from helpers.web import browser  # noqa: F401
