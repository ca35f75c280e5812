"""report stage of rclverify."""
