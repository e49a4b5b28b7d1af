// Diagnostics: the `diagnostics` channel drawn as the dashboard card (worst level per hardware id)
// and, on /diagnostics, the table of every status with its values (diagnostics/board.js draws both;
// the replay view draws a recording's board with it too).
import { on } from '../live/live.js';
import { showBoard } from './board.js';

const $ = (id) => document.getElementById(id);

on('diagnostics', (d) => showBoard(d, { hardware: $('diag-hardware'), body: $('diag-body'), empty: $('diag-empty') }));
