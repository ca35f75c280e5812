"""``rclverify import fret``: a FRET export brought into a workspace and kept in step (:mod:`.importer`)."""
