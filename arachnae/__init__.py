"""ARACHNAE II toolkit: the `arachnae` command and what its parts share."""
