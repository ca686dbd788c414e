"""Controllers: joint references, base driver, gripper. They know nothing about trees."""
