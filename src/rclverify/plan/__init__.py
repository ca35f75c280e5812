"""plan stage of rclverify."""
