"""The HAL workbench in the browser: ``halsdk web``.

:mod:`halsdk.web.server` is the command (attach, print the URL with its
token, serve until SIGINT/SIGTERM); :mod:`halsdk.web.app` the ASGI
application (starlette) with its token gate; :mod:`halsdk.web.show` the
data of the Show page over the public layer and halcmd's runner.  The
page itself is static files in ``static/`` (no build step, nothing
fetched from the internet).  See docs/web.rst.
"""
