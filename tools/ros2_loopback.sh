# shellcheck shell=bash
# ros2_loopback.sh - sourced by the benchmark scripts (jitter.sh, ros2_latency.sh): the DDS set-up
# of a measurement on the loopback, written once.
#   ros2_loopback_toml DOMAIN RATE_HZ   prints odometryd's [can] bus = "none" and [ros2] sections:
#                                       the output on, on lo only, unicast to 127.0.0.1
#   CYCLONEDDS_URI                      exported: a Cyclone DDS receiver (ros2_cyclone_peer) that
#                                       discovers the daemon the same way (lo, no multicast)

# ros2_loopback_toml DOMAIN RATE_HZ: the config sections above, on stdout.
ros2_loopback_toml() {
  cat <<TOML
[can]
bus = "none"
[ros2]
enabled = true
domain_id = $1
rate_hz = $2
interfaces = ["lo"]
multicast = false
peers = ["127.0.0.1"]
TOML
}

export CYCLONEDDS_URI='<CycloneDDS><Domain Id="any"><General><Interfaces><NetworkInterface name="lo"/></Interfaces><AllowMulticast>false</AllowMulticast></General><Discovery><ParticipantIndex>auto</ParticipantIndex><Peers><Peer address="127.0.0.1"/></Peers></Discovery></Domain></CycloneDDS>'
