"""backends stage of rclverify."""
