# Messages of the distributed run. Included before catkin_package().
add_message_files(FILES AgentState.msg FormationStatus.msg RunProgress.msg)
add_service_files(FILES RecallState.srv RecallHistory.srv)
generate_messages(DEPENDENCIES std_msgs geometry_msgs)
