"""calculus stage of rclverify."""
