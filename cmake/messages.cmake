# Messages of the distributed run. Included before catkin_package().
add_message_files(FILES AgentState.msg AgentStates.msg FormationCommand.msg FormationCommands.msg
  FormationStatus.msg RunProgress.msg WorldContact.msg)
add_service_files(FILES RecallHistory.srv RecallState.srv)
generate_messages(DEPENDENCIES geometry_msgs std_msgs)
