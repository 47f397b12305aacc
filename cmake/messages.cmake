# Messages of the distributed run. Included before catkin_package().
add_message_files(FILES AgentState.msg FormationStatus.msg RunProgress.msg)
generate_messages(DEPENDENCIES std_msgs geometry_msgs)
