# libinscribe_client (inscribe::client): the typed C++ API over the gRPC stub.
#   Client (deadlines, retries) -> Connection (interface, mockable) -> generated stub.
# Included from client/CMakeLists.txt; paths are relative to this file so it can be included
# from anywhere.
add_library(inscribe_client STATIC
  ${CMAKE_CURRENT_LIST_DIR}/src/client/client.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/client/distance_session.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/client/grpc_connection.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/client/routed_connection.cpp
  ${CMAKE_CURRENT_LIST_DIR}/src/client/scene_session.cpp)
add_library(inscribe::client ALIAS inscribe_client)
target_include_directories(inscribe_client
  PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_LIST_DIR}/include> $<INSTALL_INTERFACE:include>)
target_link_libraries(inscribe_client
  PUBLIC inscribe::core inscribe::proto inscribe::wire absl::status absl::statusor
  PRIVATE gRPC::grpc++ OpenSSL::Crypto inscribe_build_flags)
set_target_properties(inscribe_client PROPERTIES POSITION_INDEPENDENT_CODE ON)
