// defaultSocketUrl: the page's ?token= goes on to the WebSocket (control needs it on a server
// reachable from the network, docs/serve.md), and nothing changes without one.
import assert from 'node:assert/strict';
import { test } from 'node:test';

import { defaultSocketUrl } from '../src/connection.js';

const page = (search, protocol = 'http:') => ({ protocol, host: '10.0.0.5:8080', search });

test('no token: the plain /ws', () => {
  assert.equal(defaultSocketUrl(page('')), 'ws://10.0.0.5:8080/ws');
});

test('the page token is passed on, escaped', () => {
  assert.equal(defaultSocketUrl(page('?token=ab12')), 'ws://10.0.0.5:8080/ws?token=ab12');
  assert.equal(
    defaultSocketUrl(page('?x=1&token=a b', 'https:')),
    'wss://10.0.0.5:8080/ws?token=a%20b',
  );
});

test('?ws= still overrides everything', () => {
  assert.equal(defaultSocketUrl(page('?ws=ws://h:1/ws&token=t')), 'ws://h:1/ws');
});
