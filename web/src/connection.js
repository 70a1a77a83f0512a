// WebSocket link to `duet serve` (docs/protocol.md): parses JSON messages, reconnects on loss.

/**
 * The server's /ws on the host that served the page (with the page's `?token=`, which control
 * needs on a networked server), unless `?ws=URL` overrides it.
 */
export function defaultSocketUrl(location) {
  const override = new URLSearchParams(location.search).get('ws');
  if (override) return override;
  const scheme = location.protocol === 'https:' ? 'wss' : 'ws';
  // A server on the network prints its page address with ?token=...; control needs it.
  const token = new URLSearchParams(location.search).get('token');
  const query = token ? `?token=${encodeURIComponent(token)}` : '';
  return `${scheme}://${location.host}/ws${query}`;
}

const kRetryFirstS = 0.5; // first reconnect delay
const kRetryMaxS = 5; // delays double up to this

/**
 * Keeps one WebSocket open to `url`, reopening it after a loss with a doubling delay.
 * `onMessage(msg)` gets each parsed JSON object; `onOpen()` and `onClose()` report the link.
 * Malformed messages go to `onBadMessage(text, reason)` and never close the link.
 */
export class Connection {
  constructor(url, { onMessage, onOpen = () => {}, onClose = () => {}, onBadMessage = () => {} }) {
    this.url = url;
    this.connected = false;
    this.onMessage = onMessage;
    this.onOpen = onOpen;
    this.onClose = onClose;
    this.onBadMessage = onBadMessage;
    this.retry_s_ = kRetryFirstS;
    this.socket_ = null;
    this.timer_ = null;
    this.open_();
  }

  /** Sends one message; returns false (and drops it) while disconnected. */
  send(msg) {
    if (!this.connected) return false;
    this.socket_.send(JSON.stringify(msg));
    return true;
  }

  /** Bytes sent but not yet on the wire (0 while disconnected): how far the link is behind. */
  get bufferedAmount() {
    return this.socket_?.bufferedAmount ?? 0;
  }

  open_() {
    this.timer_ = null;
    let socket;
    try {
      socket = new WebSocket(this.url);
    } catch (err) {
      this.onBadMessage('', `cannot open ${this.url}: ${err.message}`);
      this.scheduleRetry_();
      return;
    }
    this.socket_ = socket;
    socket.addEventListener('open', () => {
      this.connected = true;
      this.retry_s_ = kRetryFirstS;
      this.onOpen();
    });
    socket.addEventListener('message', (event) => {
      if (typeof event.data !== 'string') {
        this.onBadMessage('', 'binary message ignored');
        return;
      }
      let msg;
      try {
        msg = JSON.parse(event.data);
      } catch (err) {
        this.onBadMessage(event.data, `not JSON: ${err.message}`);
        return;
      }
      if (msg === null || typeof msg !== 'object' || typeof msg.type !== 'string') {
        this.onBadMessage(event.data, 'not a JSON object with a "type"');
        return;
      }
      this.onMessage(msg);
    });
    // 'error' is always followed by 'close'; reconnecting is handled there.
    socket.addEventListener('close', () => {
      const was_connected = this.connected;
      this.connected = false;
      if (this.socket_ === socket) this.socket_ = null;
      if (was_connected) this.onClose();
      this.scheduleRetry_();
    });
  }

  scheduleRetry_() {
    if (this.timer_ !== null) return;
    this.timer_ = setTimeout(() => this.open_(), this.retry_s_ * 1000);
    this.retry_s_ = Math.min(this.retry_s_ * 2, kRetryMaxS);
  }
}
