"""The main job: explore -> map -> describe -> ask -> navigate -> report, on one apartment."""
