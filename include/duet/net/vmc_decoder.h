// Decodes one UDP datagram of a VMC stream (OSC: a message, or a bundle of messages and bundles)
// and hands the messages to a VmcSource (duet/live/source_vmc.h). Every OSC message is checked by
// liblo (lo_message_deserialise: address, type tags, padding, sizes); the bundle framing is walked
// here (liblo parses bundles only inside its own server, which owns a socket). A datagram that is
// not OSC, a bundle element whose size does not fit, or an address outside /VMC/ is counted as
// rejected by the source and the rest of the datagram still decodes where it can.
#pragma once

#include <cstddef>

#include "duet/live/source_vmc.h"

namespace duet::net {

// `data` is the datagram (modifiable: liblo takes a non-const pointer); `arrival` when it came.
// Ends the packet (VmcSource::end_packet) after its last message.
void decode_vmc_packet(char* data, std::size_t size, SteadyClock::time_point arrival,
                       VmcSource& source) noexcept;

}  // namespace duet::net
