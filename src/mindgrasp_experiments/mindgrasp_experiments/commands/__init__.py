"""``mindgrasp experiment <verb>`` modules (``add_arguments(parser)``, ``main(args)``)."""
