# by hand: version 4 with each coefficient's 1-sigma error
pm-model 4
mount altaz
order 0
errors
terms 7
term a 1 0 0 1e-4 2.5e-6
term b 2 0 0 -2e-4 2.5e-6
term c' 3 0 0 0.001 1e-5
term d 4 0 0 0 3e-6
term e' 5 0 0 -0.0005 1e-6
term i 6 0 0 3.5e-05 4e-6
xterm cot(el) zenith 0 0 0 0 0 0 1e-5 2e-6
end
