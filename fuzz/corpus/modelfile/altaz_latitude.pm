# by hand: an alt-az model with a latitude, comments and blank lines
pm-model 3
mount altaz
order 0
latitude 0.55301

terms 8
term a 1 0 0 1e-4
term b 2 0 0 -2e-4
term c' 3 0 0 0.001
term d 4 0 0 0
term e' 5 0 0 -0.0005
term i 6 0 0 3.5e-05
xterm cot(el) zenith 0 0 0 0 0 0 1e-5
xterm c'*aux1 aux 3 0 0 1 4 0.5 -2e-6
end
