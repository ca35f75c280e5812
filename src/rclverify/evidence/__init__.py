"""evidence stage of rclverify."""
