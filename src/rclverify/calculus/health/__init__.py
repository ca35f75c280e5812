"""health stage of rclverify."""
