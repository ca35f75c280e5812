"""system stage of rclverify."""
