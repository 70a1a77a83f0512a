// Builds the viewer into web/dist/, which `duet serve` (or tests/mock-server.mjs) serves.
// `npm run dev` proxies /ws to a running server: DUET_SERVER=host:port (default localhost:8080).
import { defineConfig } from 'vite';

const server = process.env.DUET_SERVER || 'localhost:8080';

export default defineConfig({
  // Relative asset URLs, so dist/ works whatever path the server mounts it on.
  base: './',
  build: {
    outDir: 'dist',
    emptyOutDir: true,
    // three is ~700 kB minified; the warning is noise for a local tool.
    chunkSizeWarningLimit: 1500,
  },
  server: {
    proxy: {
      '/ws': { target: `ws://${server}`, ws: true },
    },
  },
});
