"""Markers of the documentation and browser tests."""


def pytest_configure(config):
    config.addinivalue_line("markers", "browser: drives headless Chromium (Debian's /usr/bin/chromium) via playwright")
    config.addinivalue_line("markers", "docs: checks the built documentation site (make docs first)")
