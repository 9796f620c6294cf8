// Fixture for dependency_rule.includes_catches_violation: core may not see Fast DDS or threads.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <thread>
