"""Exit codes the command line and its front ends (studies, the API, the chat) share."""

from __future__ import annotations

EXIT_BAD_INPUT = 2  # a mission, world or study file (or an argument) is wrong: one-line error
EXIT_INTERRUPTED = 130  # Ctrl-C or SIGTERM: what was recorded is kept (128 + SIGINT)
