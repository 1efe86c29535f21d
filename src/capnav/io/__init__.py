"""Sources and sinks of posed RGB-D streams (dataset folders) and map files."""
