"""Scene files shipped with tumble (package data; list them with ``tumble.scenes.files()``)."""
